"""The stabilisation chart of a modal identification (matplotlib, PNG, written atomically): every
physical pole by frequency and model order, its marker saying how stable it is, the mean FRF
magnitude behind, and the chosen modes as vertical lines."""

from __future__ import annotations

import numpy as np

from .correlation_plots import _plt, _save

#: code -> (marker, colour, legend)
STYLE = {
    "o": ("o", "0.7", "new / unstable"),
    "f": ("x", "tab:orange", "stable frequency"),
    "d": ("D", "tab:purple", "frequency + damping"),
    "v": ("^", "tab:blue", "frequency + shape"),
    "s": ("s", "tab:green", "stable (all three)"),
}


def stabilisation_chart(path, result, frfs) -> None:
    """Write the chart of ``result`` (:class:`pcbdyn.identification.Identification`) over the mean
    magnitude of the FRFs it came from (``frfs``, :class:`pcbdyn.testdata.FRFs`)."""
    plt = _plt()
    c = result.chart
    lo, hi = result.band
    fig, ax = plt.subplots(figsize=(10, 6))
    for code, (marker, colour, label) in STYLE.items():
        on = c.code == code
        if on.any():
            ax.plot(c.frequency[on], c.order[on], linestyle="none", marker=marker, markersize=4, mfc="none",
                    mec=colour, label=f"{label} ({int(on.sum())})")
    for k, f in enumerate(result.modes.frequencies):
        ax.axvline(f, color="tab:red", linewidth=0.8, alpha=0.6)
        ax.text(f, 1.0, str(k + 1), transform=ax.get_xaxis_transform(), color="tab:red", fontsize=7,
                ha="center", va="bottom")
    ax.set_xlim(lo, hi)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("model order (poles)")
    mag = ax.twinx()
    band = (frfs.frequencies >= lo) & (frfs.frequencies <= hi)
    mean = np.nanmean(np.abs(frfs.H[band]).reshape(int(band.sum()), -1), axis=1)
    mag.semilogy(frfs.frequencies[band], mean, color="0.35", linewidth=0.8)
    mag.set_ylabel(f"mean |H| [{frfs.units}]")
    n = result.modes.n_modes
    ax.set_title(f"\nstabilisation chart, LSCF orders up to {2 * result.max_order}: {n} mode(s) chosen "
                 f"({result.selection})")
    ax.legend(loc="upper left", fontsize=7, framealpha=0.9)
    _save(fig, path)
