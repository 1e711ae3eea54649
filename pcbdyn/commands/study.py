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

from .common import check_writable, checked_outputs, library_option

KEYS = {"case", "levels_pct", "shots", "methods", "equations", "rank", "seed", "workers", "scheduler", "out", "board",
        "points"}
CASE_KEYS = {
    "simulated_free_pcb": {"nu", "n_modes", "errors_mm", "excitation_node", "perturbation_node", "perturbation_kg"},
    "board": {"n_modes", "params"},
}


def read_spec(path: Path) -> dict:
    """The [study] and [case] tables of ``path``, checked; ValueError names the bad field."""
    from ..inputs import read_toml
    from ..problems.cases import CASES
    from ..updating.study import METHODS

    doc = read_toml(path, ValueError)[1]
    s = doc.get("study")
    if not isinstance(s, dict):
        raise ValueError(f"{path.name}: a [study] table is required (see `pcbdyn study --help`)")
    unknown = set(s) - KEYS
    if unknown:
        raise ValueError(f"[study]: unknown key(s) {sorted(unknown)}; allowed: {sorted(KEYS)}")
    case = s.get("case", "simulated_free_pcb")
    if case not in CASES:
        raise ValueError(f"[study] case = {case!r}: choose one of {sorted(CASES)}")
    levels = s.get("levels_pct", [0, 0.5, 1, 2])
    if not isinstance(levels, list) or not levels or any(not isinstance(v, (int, float)) or v < 0 for v in levels):
        raise ValueError("[study] levels_pct: give a list of noise levels >= 0 in %, e.g. [0, 0.5, 1, 2]")
    shots = s.get("shots", 20)
    if not isinstance(shots, int) or shots < 1:
        raise ValueError("[study] shots: give a whole number >= 1 (the thesis uses 20)")
    methods = s.get("methods", ["tls-qrf", "svd-qr", "min-norm"])
    bad = [m for m in methods if m not in METHODS]
    if bad:
        raise ValueError(f"[study] methods: {bad} unknown; choose from {list(METHODS)}")
    rank = s.get("rank")
    if rank is not None and not isinstance(rank, int):
        raise ValueError("[study] rank: a whole number (k, or -k for n_params - k); omit it for automatic")
    opts = dict(doc.get("case", {}))
    unknown = set(opts) - CASE_KEYS[case]
    if unknown:
        raise ValueError(f"[case]: unknown key(s) {sorted(unknown)} for case {case!r}; allowed: {sorted(CASE_KEYS[case])}")
    if "errors_mm" in opts:
        opts["errors_mm"] = {int(k): float(v) for k, v in opts["errors_mm"].items()}
    if case == "board":
        for key in ("board", "points"):
            if key not in s:
                raise ValueError(f"[study] {key}: case 'board' needs board = \"board.toml\" and points = \"points.csv\"")
            if not (path.parent / s[key]).is_file():
                raise ValueError(f"[study] {key} = {s[key]!r}: no such file next to {path.name}")
        opts.update(path=path.parent / s["board"], points_csv=path.parent / s["points"],
                    truth=doc.get("truth", {}))
    out = s.get("out")
    if out is not None:
        try:
            check_writable(path.parent / str(out), "[study] out =", folder=True, shown=out)
        except click.UsageError as exc:
            raise ValueError(exc.message) from None
    return {
        "case": case, "case_options": opts, "levels": [float(v) for v in levels], "shots": shots,
        "methods": list(methods), "equations": list(s.get("equations", ["qms"])), "rank": rank,
        "seed": int(s.get("seed", 0)), "workers": s.get("workers"), "scheduler": s.get("scheduler"),
        "out": None if out is None else (path.parent / out),
    }


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
    from ..report.files import write_json, write_text
    from ..testdata import TestDataError
    from ..domain import StructureError
    from ..problems.cases import CASES
    from ..updating.study import run_study, summarise
    from .common import done, fail, step

    try:
        spec = read_spec(study_toml)
        t0 = step(f"building case {spec['case']}")
        case = CASES[spec["case"]](**spec["case_options"])
        done(t0)
        df = run_study(case, spec["levels"], spec["shots"], spec["methods"], spec["equations"], seed=spec["seed"],
                       rank=spec["rank"], workers=spec["workers"], progress=not quiet,
                       scheduler=scheduler or spec["scheduler"])
    except (ValueError, TypeError, KeyError, TestDataError, StructureError) as exc:
        fail(f"{study_toml.name}: {str(exc).strip(chr(34) + chr(39))}")
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
