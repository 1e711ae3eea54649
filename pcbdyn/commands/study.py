"""``pcbdyn study study.toml [--json PATH]``: success-ratio study of error localisation methods
(thesis section 5.3) over noise levels x random shots x methods x equation types.

study.toml::

    [study]
    case = "simulated_free_pcb"        # built-in case (thesis 5.4.4)
    levels_pct = [0, 0.5, 1, 2]        # uniform noise levels, eqs. 5.72-5.74
    shots = 20
    methods = ["tls-qrf", "svd-qr", "min-norm"]
    equations = ["qms"]                # qms, fbm, frf, frf+pbc
    rank = -1                          # optional: k, or -k = n_params - k; default automatic
    seed = 0
    workers = 2                        # default: all cores
    scheduler = "tcp://host:8786"      # optional: run the shots on a Dask cluster (or --scheduler)
    out = "study_out"                  # optional: CSV + PNG (relative to the toml)

    [case]                             # optional case options
    nu = 0.35
    n_modes = 7
    errors_mm = { "11" = 3.2, "13" = 3.2 }   # element -> true thickness; default Table 5.10

Any board instead (equations qms, fbm or freq)::

    [study]
    case = "board"
    board = "board.toml"               # its [[parameters]] at their values are the model
    points = "points.csv"              # measurement points
    [truth]                            # the simulated structure's parameter values
    t_PGA = "4.5 mm"
    [case]
    n_modes = 6
    params = ["t_PGA", "t_JLCC"]       # optional subset of [[parameters]]
"""

from __future__ import annotations

from pathlib import Path

import click

from ..domain import MAX_MODES, StructureError
from ..inputs import MAX_NAME
from ..units import shown
from .common import check_writable, checked_outputs, library_option

KEYS = ["case", "levels_pct", "shots", "methods", "equations", "rank", "seed", "workers", "scheduler", "out", "board",
        "points"]
#: each case's options: (kind, lower, upper) of a number, "names" (a list of names) or "elements" (element -> mm)
CASE_KEYS = {
    "simulated_free_pcb": {"nu": (float, -0.99, 0.499), "n_modes": (int, 1, 50), "errors_mm": "elements",
                           "excitation_node": (int, 1, 56), "perturbation_node": (int, 1, 56),
                           "perturbation_kg": (float, 1e-6, 1e3)},
    "board": {"n_modes": (int, 1, MAX_MODES), "params": "names"},
}


class StudyError(StructureError):
    """A study.toml that cannot be used; the message names the file, the field and the fix."""


def read_spec(path: Path) -> dict:
    """The [study], [case] and [truth] tables of ``path``, every field checked (type, range, files);
    a StudyError names the file, the field and the fix."""
    from ..inputs import Reader, read_toml
    from ..problems.cases import CASES
    from ..updating.study import METHODS

    doc = read_toml(path, StudyError)[1]
    r = Reader(path, StudyError)
    r.table(doc, "top level", ["study", "case", "truth"], required=["study"])
    s = r.table(doc["study"], "study", KEYS)
    case = s.get("case", "simulated_free_pcb")
    if not isinstance(case, str) or case not in CASES:
        r.fail("study.case", f"{shown(case)} is not a case; choose one of {sorted(CASES)}")
    levels = _numbers(r, s.get("levels_pct", [0, 0.5, 1, 2]), "study.levels_pct", 0.0, 100.0,
                      "a list of noise levels in %, from 0 to 100, e.g. [0, 0.5, 1, 2]")
    shots = _whole(r, s.get("shots", 20), "study.shots", 1, 100_000, "the thesis uses 20")
    methods = _choices(r, s.get("methods", ["tls-qrf", "svd-qr", "min-norm"]), "study.methods", list(METHODS))
    equations = _choices(r, s.get("equations", ["qms"]), "study.equations", list(CASES[case].kinds))
    rank = s.get("rank")
    if rank is not None:
        _whole(r, rank, "study.rank", -10_000, 10_000, "k, or -k for n_params - k; omit it for automatic")
    seed = _whole(r, s.get("seed", 0), "study.seed", 0, 2**63 - 1, "any whole number from 0")
    workers = None if s.get("workers") is None else _whole(r, s["workers"], "study.workers", 1, 1024, "e.g. 2")
    scheduler = None if s.get("scheduler") is None else r.text(s["scheduler"], "study.scheduler", 200)
    opts = dict(r.table(doc.get("case", {}), "case", sorted(CASE_KEYS[case])))
    for key, kind in CASE_KEYS[case].items():
        if key not in opts:
            continue
        where = f"case.{key}"
        if kind == "names":
            opts[key] = [r.text(v, f"{where}[{i}]", MAX_NAME) for i, v in enumerate(r.list(opts, key, where))]
        elif kind == "elements":
            table = r.table(opts[key], where)
            if not all(k.isdigit() and len(k) < 6 for k in table):
                r.fail(where, "keys are element numbers, e.g. { \"11\" = 3.2, \"13\" = 3.2 }")
            opts[key] = {int(k): r.number(v, f"{where}.{k}", 0.0, 1000.0) for k, v in table.items()}
        elif kind[0] is int:
            opts[key] = _whole(r, opts[key], where, kind[1], kind[2], "")
        else:
            value = r.number(opts[key], where)
            if not kind[1] <= value <= kind[2]:
                r.fail(where, f"must lie from {kind[1]:g} to {kind[2]:g}, got {value:g}")
            opts[key] = value
    if case == "board":
        files = {key: _file(r, path, s, key) for key in ("board", "points")}
        opts.update(path=files["board"], points_csv=files["points"], truth=_truth(r, doc, files["board"], opts))
    elif "truth" in doc or "board" in s or "points" in s:
        r.fail("study.board" if "board" in s else "study.points" if "points" in s else "truth",
               f"only case = \"board\" takes a board, points and a [truth] table (case is {case!r})")
    out = s.get("out")
    if out is not None:
        r.text(out, "study.out", 400)
        try:
            check_writable(path.parent / out, "[study] out =", folder=True, shown=out)
        except click.UsageError as exc:
            r.fail("study.out", exc.message)
    return {
        "case": case, "case_options": opts, "levels": levels, "shots": shots, "methods": methods,
        "equations": equations, "rank": rank, "seed": seed, "workers": workers, "scheduler": scheduler,
        "out": None if out is None else (path.parent / out),
    }


def _truth(r, doc: dict, board: Path, opts: dict) -> dict:
    """The [truth] of a board study: {parameter of the board (of ``params`` when given): SI value}."""
    from ..problems import load_structure

    try:
        params = {p.name: p for p in load_structure(board).parameters}
    except StructureError as exc:
        r.fail("study.board", str(exc))
    unknown = [n for n in opts.get("params", []) if n not in params]
    if unknown:
        r.fail("case.params", f"{shown(unknown[0])} is not a parameter of {board.name} (known: {', '.join(params)})")
    truth = r.table(doc.get("truth", {}), "truth", list(opts.get("params") or params))
    if not truth:
        r.fail("truth", "give the true value of at least one parameter, e.g. t_U1 = \"4 mm\"")
    out = {}
    for k, v in truth.items():
        unit = params[k].unit
        out[k] = r.number(v, f"truth.{k}") if unit == "1" and not isinstance(v, str) else r.q(v, unit, f"truth.{k}")
    return out


def _whole(r, value, where, lo, hi, example) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        r.fail(where, f"must be a whole number from {lo} to {hi}, got {shown(value)}" + (f" ({example})" if example else ""))
    return value


def _numbers(r, value, where, lo, hi, example) -> list:
    if not isinstance(value, list) or not value or len(value) > 100:
        r.fail(where, f"give {example}, got {shown(value)}")
    out = [r.number(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if not all(lo <= v <= hi for v in out):
        r.fail(where, f"give {example}, got {shown(value)}")
    return out


def _choices(r, value, where, allowed) -> list:
    if not isinstance(value, list) or not value or len(value) > 20:
        r.fail(where, f"give a list of some of {allowed}, got {shown(value)}")
    bad = [v for v in value if not isinstance(v, str) or v not in allowed]
    if bad:
        r.fail(where, f"{shown(bad[0])} is unknown; choose from {allowed}")
    return list(value)


def _file(r, path: Path, s: dict, key: str) -> Path:
    if key not in s:
        r.fail(f"study.{key}", "missing: case 'board' needs board = \"board.toml\" and points = \"points.csv\"")
    name = r.text(s[key], f"study.{key}", 400)
    if not (path.parent / name).is_file():
        r.fail(f"study.{key}", f"{name!r}: no such file next to {path.name}")
    return path.parent / name


@click.command("study")
@click.argument("study_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path),
              help="write the summary and every shot's result as JSON ('-': standard output)")
@click.option("--scheduler", default=None, help="a Dask scheduler address (tcp://host:8786): the shots run on that "
                                                "cluster instead of local processes (same results)")
@click.option("--quiet", is_flag=True, help="no progress bar")
@checked_outputs(folders=())
@library_option()
def command(study_toml: Path, json_path: Path | None, scheduler: str | None, quiet: bool):
    """Judge localisation methods by their success ratio over noisy random shots (thesis eq. 5.65-5.66)."""
    from ..problems.cases import CASES, CaseError
    from ..report.files import write_json, write_text
    from ..updating.study import run_study, summarise
    from .common import done, input_errors, step

    with input_errors():
        spec = read_spec(study_toml)
        t0 = step(f"building case {spec['case']}")
        try:
            case = CASES[spec["case"]](**spec["case_options"])
        except CaseError as exc:
            raise StudyError(f"{study_toml.name}: {exc}") from None
        done(t0)
        df = run_study(case, spec["levels"], spec["shots"], spec["methods"], spec["equations"], seed=spec["seed"],
                       rank=spec["rank"], workers=spec["workers"], progress=not quiet,
                       scheduler=scheduler or spec["scheduler"])
    summary = summarise(df)
    true = [case.parameter_names[i] for i in case.true_errors]
    click.echo(f"\n{spec['case']}: true errors {', '.join(true)}; {spec['shots']} shots per level")
    table = summary.pivot_table(index=["equations", "level_pct"], columns="method", values="mean")
    click.echo("mean success ratio [%]:\n" + table.round(1).to_string() + "\n")
    if spec["out"] is not None:
        from ..report.localisation_plots import success_ratio_figure

        from ..report.manifest import settle

        written = [spec["out"] / name for name in ("shots.csv", "summary.csv", "success_ratios.png")]
        write_text(written[0], df.to_csv(index=False))
        write_text(written[1], summary.to_csv(index=False))
        success_ratio_figure(written[2], summary)
        settle(spec["out"], written, "pcbdyn study")
        click.echo(f"wrote {spec['out']}/shots.csv, summary.csv, success_ratios.png", err=True)
    if json_path is not None:
        write_json(json_path, {"case": spec["case"], "true_errors": true,
                               "summary": summary.to_dict(orient="records"), "shots": df.to_dict(orient="records")})
