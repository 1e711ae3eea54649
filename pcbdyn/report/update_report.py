"""Reports of a model update: parameter table, before/after correlation tables, iteration plots and
the updated board.toml (written next to the original, never over it)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np

from ..units import registry


def in_unit(value_si: float, unit: str) -> float:
    """A SI value expressed in ``unit`` (e.g. 0.0035 -> 3.5 for "mm")."""
    return float(registry().Quantity(value_si, registry().Quantity(1.0, unit).to_base_units().units).to(unit).magnitude)


def parameter_rows(problem, p) -> list:
    """One dict per parameter: name, unit, initial/updated (in the board's unit), change %, bound hit."""
    lo, hi = problem.bounds
    rows = []
    for i, (par, v0, v) in enumerate(zip(problem.parameters, problem.p0, p)):
        hit = "lower" if np.isclose(v, lo[i], rtol=1e-6) else "upper" if np.isclose(v, hi[i], rtol=1e-6) else ""
        rows.append({"name": par.name, "unit": par.unit, "initial": in_unit(v0, par.unit), "updated": in_unit(v, par.unit),
                     "change_pct": 100.0 * (v / v0 - 1.0), "bound_hit": hit, "log_scale": i in problem.log_scale})
    return rows


def format_parameters(rows) -> str:
    out = [f"{'parameter':>14} {'unit':>10} {'initial':>12} {'updated':>12} {'change [%]':>11}  bound"]
    for r in rows:
        out.append(f"{r['name']:>14} {r['unit']:>10} {r['initial']:>12.5g} {r['updated']:>12.5g} "
                   f"{r['change_pct']:>+11.2f}  {r['bound_hit']}")
    return "\n".join(out)


def format_correlation(before, after) -> str:
    """Per configuration: test mode, f_test, f_model and df before and after, MAC after."""
    out = []
    for b, a in zip(before, after):
        out.append(f"[{b['configuration']}] max |df|: {b['max_freq_error_pct']:.2f} % -> {a['max_freq_error_pct']:.2f} %")
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
    ax[2].semilogy(it, [h["condition_stacked"] for h in result.history], "o-")
    ax[2].set(xlabel="iteration", ylabel="condition number", title="stacked equations")
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


# --- updated board.toml -------------------------------------------------------------------------

def _find(items, key, value, where):
    for it in items:
        if str(it.get(key)) == value:
            return it
    raise KeyError(f"{where}: no entry with {key} = '{value}'")


def _slot(data, board, target):
    """(table, key) holding ``target`` in the raw TOML data."""
    parts = target.split(".")
    if parts[0] == "board":
        b = data["board"]
        if parts[1] == "thickness":
            return b, "thickness"
        mat = b.get("material")
        if not isinstance(mat, dict):
            iso = board.isotropic
            b["material"] = mat = {"E": f"{iso.E!r} Pa", "nu": iso.nu, "rho": f"{iso.rho!r} kg/m^3"}
        return mat, parts[1]
    kind, name, attr = parts
    if kind == "components":
        return _find(data.get("components", []), "ref", name, "components"), attr
    if kind == "fixtures":
        i = [f.name for f in board.fixtures].index(name)
        return data["fixtures"][i], attr
    if kind == "masses":
        i = [m.name for m in board.masses].index(name)
        return data["masses"][i], attr
    raise KeyError(f"target '{target}' cannot be written to board.toml")


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def dumps_toml(data: dict) -> str:
    """TOML text of a board.toml-shaped dict: top-level tables and arrays of tables whose values are
    scalars, arrays and inline tables."""
    out = []
    for name, v in data.items():
        if isinstance(v, dict):
            out.append(f"[{_key(name)}]")
            out += [f"{_key(k)} = {_value(x)}" for k, x in v.items()]
            out.append("")
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for item in v:
                out.append(f"[[{_key(name)}]]")
                out += [f"{_key(k)} = {_value(x)}" for k, x in item.items()]
                out.append("")
        else:
            out.insert(0, f"{_key(name)} = {_value(v)}")
    return "\n".join(out)


def updated_board_path(board_toml) -> Path:
    p = Path(board_toml)
    return p.with_name(f"{p.stem}.updated{p.suffix}")


def write_updated_board(board_toml, board, problem, p) -> Path:
    """board.updated.toml next to ``board_toml`` with the updated parameter values in their units
    (comments of the original are not kept). Returns the path written."""
    from .files import write_text

    src = Path(board_toml)
    data = tomllib.loads(src.read_text())
    for par, v in zip(problem.parameters, p):
        text = f"{in_unit(v, par.unit):.6g} {par.unit}"
        for t in par.targets:
            table, key = _slot(data, board, t)
            table[key] = text
    dst = updated_board_path(src)
    header = (f"# {src.name} with the parameters updated by 'pcbdyn update' "
              f"({', '.join(problem.names)}).\n\n")
    write_text(dst, header + dumps_toml(data))
    return dst
