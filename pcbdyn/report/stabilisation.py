"""The stabilisation chart of a modal identification (matplotlib, PNG, written atomically): every
physical pole by frequency and model order, its marker saying how stable it is, the mean FRF
magnitude behind, and the chosen modes as vertical lines."""

from __future__ import annotations

import numpy as np

from .files import PLOT, pyplot, save_figure
from .labels import place_labels

#: code -> (marker, colour, legend)
STYLE = {
    "o": ("o", "0.7", "new / unstable"),
    "f": ("x", "tab:orange", "stable frequency"),
    "d": ("D", "tab:purple", "frequency + damping"),
    "v": ("^", "tab:blue", "frequency + shape"),
    "s": ("s", "tab:green", "stable (all three)"),
}
#: offsets [points] of a mode's number above the chart: rows tried from the lowest
ROWS = [(0, 2), (0, 11), (0, 20)]


def stabilisation_chart(path, result, frfs) -> None:
    """Write the chart of ``result`` (:class:`pcbdyn.identification.Identification`) over the mean
    magnitude of the FRFs it came from (``frfs``, :class:`pcbdyn.testdata.FRFs`)."""
    plt = pyplot()
    c = result.chart
    lo, hi = result.band
    fig, ax = plt.subplots(figsize=(10, 6))
    for code, (marker, colour, label) in STYLE.items():
        on = c.code == code
        if on.any():
            ax.plot(c.frequency[on], c.order[on], linestyle="none", marker=marker, markersize=4, mfc="none",
                    mec=colour, label=f"{label} ({int(on.sum())})")
    for f in result.modes.frequencies:
        ax.axvline(f, color="tab:red", linewidth=0.8, alpha=0.6)
    ax.set_xlim(lo, hi)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("model order (poles)")
    mag = ax.twinx()
    band = (frfs.frequencies >= lo) & (frfs.frequencies <= hi)
    mean = np.nanmean(np.abs(frfs.H[band]).reshape(int(band.sum()), -1), axis=1)
    mag.semilogy(frfs.frequencies[band], mean, color="0.35", linewidth=0.8)
    mag.set_ylabel(f"mean |H| [{frfs.units}]")
    n = result.modes.n_modes
    ax.set_title(f"stabilisation chart, LSCF orders up to {2 * result.max_order}: {n} mode(s) chosen "
                 f"({result.selection})", pad=8 + 9 * len(ROWS))
    ax.legend(loc="upper left", fontsize=7, framealpha=0.9)
    # the chosen modes' numbers above the chart, a row higher where a neighbour's would overlap
    place_labels(ax, [(f, 1.0) for f in result.modes.frequencies], [str(k + 1) for k in range(n)],
                 xycoords=ax.get_xaxis_transform(), offsets=ROWS, color="tab:red", fontsize=7)
    save_figure(fig, path, **PLOT)
