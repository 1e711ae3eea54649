"""Reports of the two-step wedge-lock fit (thesis section 7.4), from its JSON-ready summary
(:meth:`pcbdyn.problems.wedgelock.WedgeLockResult.to_dict`): the extremes as the thesis' Tables 7.12-7.13
show them, the decision, the fitted stiffness with its 1-sigma factor, the iteration history (Figs.
7.38-7.39) and each mode's frequency against the guides' stiffness with the test's value marked."""

from __future__ import annotations

import numpy as np

from .files import PLOT, pyplot, save_figure
from .update_report import format_correlation

UNIT = "N*m/rad/m"


def format_extreme(name: str, extreme: dict, tolerance: list) -> str:
    """One extreme per configuration: test and model mode, frequencies, df = (f_model - f_test) / f_test,
    MAC, the tolerance, and the model modes with no test partner (as the thesis notes under its tables)."""
    out = [f"{name}: max |df| {_pct(extreme['max_abs_freq_error_pct'])}"]
    for c, tol in zip(extreme["configurations"], tolerance):
        out.append(f"[{c['configuration']}]")
        out.append(f"{'test':>5} {'f_test [Hz]':>12} {'model':>6} {'f_model [Hz]':>13} {'df [%]':>8} {'MAC':>6} "
                   f"{'tol [%]':>8}")
        for q in c["pairs"]:
            mac = "" if q["mac"] is None else f"{q['mac']:.3f}"
            out.append(f"{q['test_mode']:>5d} {q['f_test_hz']:>12.2f} {q['model_mode']:>6d} {q['f_model_hz']:>13.2f} "
                       f"{q['df_pct']:>+8.2f} {mac:>6} {tol[str(q['test_mode'])]:>8.2f}")
        if c["unpaired_test_modes"]:
            out.append(f"test modes with no model partner: {', '.join(map(str, c['unpaired_test_modes']))}")
        if c["unpaired_model_modes"]:
            out.append("model modes with no test partner: " + ", ".join(
                f"#{m['model_mode']} ({m['f_model_hz']:.1f} Hz)" for m in c["unpaired_model_modes"]))
    return "\n".join(out)


def format_stiffness(k_rot: dict) -> str:
    """Per guide: the model, k and its 1-sigma range k / factor .. k * factor."""
    out = [f"{'guide':>16} {'model':>8} {'k [' + UNIT + ']':>20} {'factor (1 sigma)':>17} {'1-sigma range':>24}  bound"]
    for name, v in k_rot.items():
        if v["value"] is None:
            out.append(f"{name:>16} {v['model']:>8} {'-':>20} {'-':>17} {'-':>24}")
            continue
        k, f = v["value"], v["factor_1sigma"]
        out.append(f"{name:>16} {v['model']:>8} {k:>20.5g} {f:>17.3g} {f'{k / f:.4g} .. {k * f:.4g}':>24}  "
                   f"{v.get('bound_hit') or ''}")
    return "\n".join(out)


def format_summary(d: dict) -> str:
    """The decision, its reason, the spring fits of step 2 (kept or not) and the notes."""
    lines = [f"decision: {d['decision']}", f"  {d['reason']}"]
    for name, f in d.get("fits", {}).items():
        ks = ", ".join(f"{g} {v['value']:.4g} (x/ {v['factor_1sigma']:.3g})" for g, v in f["k_rot"].items())
        state = "kept" if f["chosen"] and d["decision"] == "springs" else "not kept"
        lines.append(f"step 2, {name.replace('_', ' ')} stiffness ({state}): {ks} {UNIT}; {f['status']}; max |df| "
                     f"{f['max_freq_error_pct']:.2f} %, chi^2 {f['chi2']:.3g} over {f['modes']} modes")
        lines += [f"  {n}" for n in f["notes"]]
    lines += [f"note: {n}" for n in d["notes"]]
    return "\n".join(lines)


def format_before_after(d: dict, before, after) -> str:
    """Step 2's correlation at its start (the best of the scan) and after the fit, or the clamped model
    when step 2 did not run (:func:`.update_report.format_correlation`)."""
    if not d["history"]:
        title = "clamped guides (no spring fit needed)"
    else:
        first, last = d["start"], next(f for f in d["fits"].values() if f["chosen"])["k_rot"]
        moves = ", ".join(f"{g} {first[g]:.4g} -> {last[g]['value']:.4g}" for g in d["guides"])
        title = f"step 2, springs: {moves} {UNIT}"
    return title + "\n" + format_correlation(before, after)


def _pct(v) -> str:
    return "-" if v is None else f"{v:.2f} %"


def plot_history(path, d: dict) -> None:
    """Per iteration: max |df| and the frequency residue [%] (thesis Fig. 7.38) and each guide's
    stiffness on a log scale (Fig. 7.39)."""
    plt = pyplot()
    h = d["history"]
    it = [e["iteration"] for e in h]
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    ax[0].plot(it, [e["max_freq_error_pct"] for e in h], "o-", label="max |df|")
    ax[0].plot(it, [e["residue_pct"] for e in h], "s--", label="residue (rms)")
    ax[0].set(xlabel="iteration", ylabel="[%]", title="frequency errors")
    ax[0].legend(fontsize=8)
    for name in d["guides"]:
        ax[1].semilogy(it, [e["k_rot"][name] for e in h], "o-", label=name)
    ax[1].set(xlabel="iteration", ylabel=f"k_rot [{UNIT}]", title="guide stiffness")
    ax[1].legend(fontsize=8)
    for a in ax:
        a.set_xticks(it)
    fig.tight_layout()
    save_figure(fig, path, **PLOT)


def plot_frequencies(path, d: dict) -> None:
    """Each paired test mode's model frequency against a stiffness shared by the guides (the scan
    between the extremes), the hinged and clamped values as its limits, the test's frequency with its
    tolerance band, and the fitted stiffness of each guide (dashed when the springs were not kept)."""
    plt = pyplot()
    k = np.asarray(d["scan"]["k"])
    modes = [(c["configuration"], m) for c in d["scan"]["configurations"] for m in c["test_modes"]]
    limits = {kind: {(c["configuration"], q["test_mode"]): q["f_model_hz"]
                     for c in d["extremes"][kind]["configurations"] for q in c["pairs"]}
              for kind in ("hinged", "clamped")}
    tol = {(c["configuration"], int(t)): v for c, per in zip(d["scan"]["configurations"], d["tolerance_pct"])
           for t, v in per.items()}
    fit = next(f for f in d["fits"].values() if f["chosen"])
    fitted, kept = sorted({v["value"] for v in fit["k_rot"].values()}), d["decision"] == "springs"
    ncol = min(3, len(modes))
    nrow = int(np.ceil(len(modes) / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.2 * nrow), squeeze=False)
    for ax, (config, m) in zip(axes.ravel(), modes):
        key = (config, m["test_mode"])
        f = np.array([np.nan if v is None else v for v in m["f_model_hz"]])
        ax.semilogx(k, f, "k.-", label="model")
        for kind, style in (("hinged", ":"), ("clamped", "--")):
            if key in limits[kind]:
                ax.axhline(limits[kind][key], color="grey", linestyle=style, linewidth=1, label=kind)
        ft, band = m["f_test_hz"], m["f_test_hz"] * tol.get(key, 0.0) / 100.0
        ax.axhspan(ft - band, ft + band, color="tab:red", alpha=0.15)
        ax.axhline(ft, color="tab:red", label="test")
        for v in fitted:
            ax.axvline(v, color="tab:blue", linewidth=1, linestyle="-" if kept else "--", alpha=0.7)
        ax.set(xlabel=f"k_rot [{UNIT}]", ylabel="f [Hz]", title=f"[{config}] test mode {m['test_mode']}")
    for ax in axes.ravel()[len(modes):]:
        ax.axis("off")
    axes.ravel()[0].legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, **PLOT)
