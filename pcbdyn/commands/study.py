"""``pcbdyn study study.toml [--out DIR] [--json PATH]``: success-ratio study of error localisation methods
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

from .common import checked_outputs, library_option


@click.command("study")
@click.argument("study_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="folder for the shots and the summary (CSV) and the success ratios (PNG)")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path),
              help="write the summary and every shot's result as JSON ('-': standard output)")
@click.option("--scheduler", default=None, help="a Dask scheduler address (tcp://host:8786): the shots run on that "
                                                "cluster instead of local processes (same results)")
@click.option("--quiet", is_flag=True, help="no progress bar")
@checked_outputs()
@library_option()
def command(study_toml: Path, out: Path | None, json_path: Path | None, scheduler: str | None, quiet: bool):
    """Judge localisation methods by their success ratio over noisy random shots (thesis eq. 5.65-5.66)."""
    from ..problems.study_spec import build_case, read_spec
    from ..report.files import write_json, write_text
    from ..updating.study import run_study, summarise
    from .common import done, input_errors, step

    with input_errors():
        spec = read_spec(study_toml)
        t0 = step(f"building case {spec['case']}")
        case = build_case(study_toml, spec)
        done(t0)
        df = run_study(case, spec["levels"], spec["shots"], spec["methods"], spec["equations"], seed=spec["seed"],
                       rank=spec["rank"], workers=spec["workers"], progress=not quiet,
                       scheduler=scheduler or spec["scheduler"])
    summary = summarise(df)
    true = [case.parameter_names[i] for i in case.true_errors]
    click.echo(f"\n{spec['case']}: true errors {', '.join(true)}; {spec['shots']} shots per level")
    table = summary.pivot_table(index=["equations", "level_pct"], columns="method", values="mean")
    click.echo("mean success ratio [%]:\n" + table.round(1).to_string() + "\n")
    if out is not None:
        from ..report.localisation_plots import success_ratio_figure
        from ..report.manifest import replacing

        with replacing(out, "pcbdyn study") as run:  # the earlier --out stays whole until all is written
            write_text(run.path / "shots.csv", df.to_csv(index=False))
            write_text(run.path / "summary.csv", summary.to_csv(index=False))
            success_ratio_figure(run.path / "success_ratios.png", summary)
        click.echo(f"wrote {out}/shots.csv, summary.csv, success_ratios.png", err=True)
    if json_path is not None:
        write_json(json_path, {"case": spec["case"], "true_errors": true,
                               "summary": summary.to_dict(orient="records"), "shots": df.to_dict(orient="records")})
