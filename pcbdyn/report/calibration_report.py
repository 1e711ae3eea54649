"""Reports of a library calibration and of the library itself: family tables, the other fitted
parameters, the runs behind a family value and their plot (value and band against the runs)."""

from __future__ import annotations

import math

from ..units import from_si, printed_unit
from .files import save_figure
from .update_report import format_correlation

__all__ = ["format_correlation", "format_families", "format_library", "format_runs", "format_with", "headline",
           "library_rows", "plot_runs", "with_rows"]


def _mm(v, digits=4) -> str:
    return "-" if v is None or not math.isfinite(v) else f"{from_si(v, 'mm'):.{digits}g}"


def headline(cal, status: str) -> str:
    r = cal.result
    return (f"calibration of {', '.join(cal.families)} from {len(cal.items)} board(s), method {cal.method}/"
            f"{cal.solver}: {status} after {r.iterations} iteration(s) ({r.reason}); {cal.noise}")


def format_families(fams: dict) -> str:
    """One row per family: the value the run started from, this run's estimate +- sd, the library's
    pooled value +- sd after it, runs on file, flag."""
    out = [f"{'family':>8} {'before [mm]':>12} {'this run [mm]':>20} {'library now [mm]':>20} {'runs':>5}  flag"]
    for fam, d in fams.items():
        run = f"{_mm(d['run_m'])} +- {_mm(d['run_std_m'], 2)}"
        lib = f"{_mm(d['equivalent_thickness_m'])} +- {_mm(d['std_m'], 2)}"
        out.append(f"{fam:>8} {_mm(d['before_m']):>12} {run:>20} {lib:>20} {d['n_calibrations']:>5}  "
                   f"{'flagged' if d['flagged'] else ''}")
    return "\n".join(out)


def with_rows(cal) -> dict:
    """{name: initial, updated, std (SI), unit} of the parameters fitted beside the families."""
    out = {}
    for i, (name, par) in enumerate(zip(cal.problem.names, cal.problem.parameters)):
        if name in cal.families:
            continue
        sd = float(cal.std[i])
        out[name] = {"initial": float(cal.problem.p0[i]), "updated": float(cal.result.p[i]),
                     "std": sd if math.isfinite(sd) else None, "display_unit": printed_unit(par.unit)}
    return out


def format_with(cal) -> str:
    out = [f"{'parameter':>24} {'unit':>10} {'initial':>12} {'updated':>12} {'+- sd':>10}"]
    for name, r in with_rows(cal).items():
        u = r["display_unit"]
        sd = "-" if r["std"] is None else f"{from_si(r['std'], u):.3g}"
        out.append(f"{name:>24} {u:>10} {from_si(r['initial'], u):>12.5g} {from_si(r['updated'], u):>12.5g} {sd:>10}")
    return "\n".join(out)


def library_rows(entries) -> list:
    """One dict per library file: family, value, std, runs (pooled/flagged), mass, size, model, file."""
    rows = []
    for path, pkg, records in entries:
        rows.append({"family": pkg.name, "equivalent_thickness_m": pkg.equivalent_thickness,
                     "std_m": pkg.equivalent_thickness_std, "n_calibrations": len(records),
                     "n_flagged": sum(r.flagged for r in records), "mass_kg": pkg.mass, "size_m": list(pkg.size),
                     "default_model": pkg.default_model, "file": str(path)})
    return rows


def format_library(rows) -> str:
    out = [f"{'family':>8} {'t_eq [mm]':>10} {'+- sd [mm]':>11} {'runs':>5} {'flagged':>8} {'mass [g]':>9} "
           f"{'size [mm]':>12} {'model':>21}  file"]
    for r in rows:
        size = " x ".join(f"{from_si(v, 'mm'):g}" for v in r["size_m"])
        out.append(f"{r['family']:>8} {_mm(r['equivalent_thickness_m']):>10} {_mm(r['std_m'], 2):>11} "
                   f"{r['n_calibrations']:>5} {r['n_flagged']:>8} {from_si(r['mass_kg'], 'g'):>9.4g} {size:>12} "
                   f"{r['default_model']:>21}  {r['file']}")
    return "\n".join(out)


def format_runs(records) -> str:
    """The calibration runs of a family, oldest first."""
    out = [f"{'#':>3} {'date (UTC)':>20} {'method':>6} {'value [mm]':>11} {'+- sd':>7} {'before':>7} "
           f"{'df before/after [%]':>20}  boards / flag"]
    for i, r in enumerate(records, 1):
        boards = ", ".join(b.get("file", "?") for b in r.boards)
        err = f"{r.max_freq_error_before_pct:.2f} / {r.max_freq_error_after_pct:.2f}"
        out.append(f"{i:>3} {r.date.strftime('%Y-%m-%d %H:%M:%S'):>20} {r.method:>6} {_mm(r.value):>11} "
                   f"{_mm(r.std, 2):>7} {_mm(r.before):>7} {err:>20}  {boards}"
                   + (f"  FLAGGED: {r.reason}" if r.flagged else ""))
    return "\n".join(out)


def plot_runs(path, family: str, records, pooled, default: float | None = None) -> None:
    """Each run's value +- sd (flagged runs as crosses) and the pooled value with its 1 and 3 sd band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    x = list(range(1, len(records) + 1))
    if pooled is not None:
        v, s = from_si(pooled.value, "mm"), from_si(pooled.std, "mm")
        ax.axhspan(v - 3 * s, v + 3 * s, color="tab:blue", alpha=0.08, label="pooled +- 3 sd")
        ax.axhspan(v - s, v + s, color="tab:blue", alpha=0.2, label="pooled +- 1 sd")
        ax.axhline(v, color="tab:blue", label=f"pooled {v:.4g} mm ({pooled.n} runs)")
    if default is not None:
        ax.axhline(from_si(default, "mm"), color="grey", ls="--", label="first run's starting value")
    for flagged, style, label in ((False, {"fmt": "o", "color": "k"}, "runs"),
                                  (True, {"fmt": "x", "color": "tab:red"}, "flagged runs")):
        sel = [(xi, r) for xi, r in zip(x, records) if r.flagged == flagged and math.isfinite(r.std)]
        if sel:
            ax.errorbar([xi for xi, _ in sel], [from_si(r.value, "mm") for _, r in sel],
                        yerr=[from_si(r.std, "mm") for _, r in sel], capsize=3, label=label, **style)
    ax.set(xlabel="calibration run", ylabel="equivalent thickness [mm]", title=f"{family}: calibration runs")
    ax.set_xticks(x)
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
