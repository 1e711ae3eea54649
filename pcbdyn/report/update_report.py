"""Reports of a model update: parameter table, before/after correlation tables, progress lines,
iteration plots and the JSON."""

from __future__ import annotations


import numpy as np

from ..units import from_si, printed_unit
from ..updating.driver import at_bounds
from .files import save_figure

#: SI unit of the JSON values for the display units the input files use (others are SI already)
SI_UNITS = {"mm": "m", "g": "kg", "GPa": "Pa"}


def parameter_rows(problem, p) -> list:
    """One dict per parameter: name, unit, initial/updated (in the unit printed for the board's,
    :func:`pcbdyn.units.printed_unit`: a modulus in GPa), change %, bound hit."""
    hits = at_bounds(problem.names, p, problem.bounds)
    rows = []
    for i, (par, v0, v) in enumerate(zip(problem.parameters, problem.p0, p)):
        hit = hits.get(par.name, "")
        u = printed_unit(par.unit)
        rows.append({"name": par.name, "unit": u, "initial": from_si(v0, u), "updated": from_si(v, u),
                     "change_pct": 100.0 * (v / v0 - 1.0), "bound_hit": hit, "log_scale": i in problem.log_scale})
    return rows


def format_parameters(rows) -> str:
    out = [f"{'parameter':>14} {'unit':>10} {'initial':>12} {'updated':>12} {'change [%]':>11}  bound"]
    for r in rows:
        out.append(f"{r['name']:>14} {r['unit']:>10} {r['initial']:>12.5g} {r['updated']:>12.5g} "
                   f"{r['change_pct']:>+11.2f}  {r['bound_hit']}")
    return "\n".join(out)


def _pct(v) -> str:
    return "(none paired)" if v is None else f"{v:.2f} %"


def format_correlation(before, after) -> str:
    """Per configuration: test mode, f_test, f_model and df before and after, MAC after."""
    out = []
    for b, a in zip(before, after):
        out.append(f"[{b['configuration']}] max |df|: {_pct(b['max_freq_error_pct'])} -> {_pct(a['max_freq_error_pct'])}")
        out.append(f"{'test':>5} {'f_test':>9} {'model':>6} {'f_before':>9} {'df [%]':>8} {'model':>6} {'f_after':>9} "
                   f"{'df [%]':>8} {'MAC':>6}")
        after_by = {q["test_mode"]: q for q in a["pairs"]}
        for q in b["pairs"]:
            r = after_by.get(q["test_mode"])
            tail = (f"{r['model_mode']:>6d} {r['f_model_hz']:>9.2f} {r['df_pct']:>+8.2f} "
                    f"{'' if r['mac'] is None else format(r['mac'], '.3f'):>6}") if r else "  (unpaired)"
            out.append(f"{q['test_mode']:>5d} {q['f_test_hz']:>9.2f} {q['model_mode']:>6d} {q['f_model_hz']:>9.2f} "
                       f"{q['df_pct']:>+8.2f} {tail}")
    return "\n".join(out)


def plot_iterations(path, problem, result) -> None:
    """Parameters (relative to initial), max frequency error and frequency residue per iteration."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    it = [h["iteration"] for h in result.history]
    P = np.array([h["p"] / problem.p0 for h in result.history])
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    for j, name in enumerate(problem.names):
        ax[0].plot(it, P[:, j], "o-", label=name)
    ax[0].set(xlabel="iteration", ylabel="p / p0", title="parameters")
    ax[0].legend(fontsize=7)
    err = [h["max_freq_error_pct"] for h in result.history]
    ax[1].plot(it, err, "o-")
    ax[1].set(xlabel="iteration", ylabel="max |df| [%]", title="max frequency error")
    ax[2].semilogy(it, [_finite(h["condition_stacked"]) for h in result.history], "o-")
    ax[2].set(xlabel="iteration", ylabel="condition number", title="stacked equations")
    fig.tight_layout()
    save_figure(fig, path, dpi=100)


def _finite(v):
    """A number for JSON and plots: None for NaN or infinity (an undefined condition number)."""
    return float(v) if v is not None and np.isfinite(v) else None


def progress_line(h: dict) -> str:
    """One line per iteration of the update (its history entry ``h``)."""
    err = "" if h["max_freq_error_pct"] is None else f"max |df| {h['max_freq_error_pct']:.3f} %, "
    aside = f"; set aside: {', '.join(h['set_aside'])}" if h.get("set_aside") else ""
    return f"    iteration {h['iteration']}: {err}residual {h['residual_norm']:.4g}{aside}"


def _summary(states) -> dict:
    errors = [s["max_freq_error_pct"] for s in states if s["max_freq_error_pct"] is not None]
    return {"max_freq_error_pct": max(errors) if errors else None, "configurations": states,
            "pairs": [q for s in states for q in s["pairs"]]}


def update_json(problem, res, rows, before, after, what: dict, method: str, solver: str, dst, fitted=None) -> dict:
    """The JSON of ``pcbdyn update`` (values in SI; ``unit`` is the SI unit of each parameter; the fit's
    verdict, noise, starts and shapes from :meth:`pcbdyn.problems.fit.Fit.summary` for the modal methods;
    ``updated_board`` None when none was written)."""
    extra = {} if fitted is None else {k: v for k, v in fitted.summary().items() if k not in ("status", "details")}
    return {
        "parameters": {r["name"]: {"initial": float(v0), "updated": float(v), "unit": SI_UNITS.get(r["unit"], r["unit"]),
                                   "display_unit": r["unit"], "change_pct": r["change_pct"], "bound_hit": r["bound_hit"]}
                       for r, v0, v in zip(rows, problem.p0, res.p)},
        "before": _summary(before), "after": _summary(after), "iterations": res.iterations,
        "converged": bool(res.converged), "reason": res.reason, "status": what["status"],
        "status_details": what["details"], "warnings": what["warnings"], "method": method, "solver": solver,
        "history": [{"iteration": h["iteration"], "p": np.asarray(h["p"]).tolist(),
                     "max_freq_error_pct": h["max_freq_error_pct"], "condition_stacked": _finite(h["condition_stacked"]),
                     "rank": h.get("rank"), "set_aside": h.get("set_aside", [])} for h in res.history],
        "updated_board": None if dst is None else str(dst), **extra,
    }


def correlation_rows(before, after) -> list:
    """The rows of :func:`format_correlation` as dicts with units in the keys (a page's table)."""
    out = []
    for b, a in zip(before, after):
        after_by = {q["test_mode"]: q for q in a["pairs"]}
        for q in b["pairs"]:
            r = after_by.get(q["test_mode"], {})
            out.append({"configuration": b["configuration"], "test mode": q["test_mode"], "f_test [Hz]": q["f_test_hz"],
                        "f before [Hz]": q["f_model_hz"], "df before [%]": q["df_pct"],
                        "f after [Hz]": r.get("f_model_hz"), "df after [%]": r.get("df_pct"), "MAC after": r.get("mac")})
    return out


def html_page(out, board_toml, board, rows, before, after, what: dict, updated, iterations_png):
    """report.html in ``out``: the status, the parameters, the correlation before and after, an animated
    3-D view of the modes of the ``updated`` model = (built model, modes) and the iteration plot."""
    import pandas as pd

    from .html import Page, describe_file
    from .view3d import shapes_view

    page = Page(f"pcbdyn update: {board.name}", subtitle=what["status"])
    page.items("Inputs", {"board": describe_file(board_toml)})
    if what["details"]:
        page.text("Notes", what["details"])
    page.table("Parameters", pd.DataFrame([{"parameter": r["name"], "unit": r["unit"], "initial": r["initial"],
                                            "updated": r["updated"], "change [%]": r["change_pct"],
                                            "bound": r["bound_hit"] or "-"} for r in rows]))
    page.table("Correlation before and after", pd.DataFrame(correlation_rows(before, after)))
    built, modes = updated
    if modes.frequencies.size:
        page.view3d("Modes of the updated model", shapes_view(
            f"{board.name} (updated)", built.model, board.outlines(None), modes.shapes,
            [f"mode {k + 1}: {f:.1f} Hz" for k, f in enumerate(modes.frequencies)]))
    page.pictures("Iterations", [iterations_png], ["parameters, largest frequency error and condition per iteration"])
    return page.write(out / "report.html")
