"""``pcbdyn calibrate board.toml test.uff [c2=more.uff ...] --library DIR [--families PGA,CQFP] [--with board.E]
[--method freq|qms|fbm] [--joint calibration.toml] --json PATH``: part families' equivalent thicknesses
(thesis section 7.3, eq. 7.7) fitted to modal tests and written into the component library DIR.

One parameter per family, shared by all its parts on every board; ``--with`` fits other quantities
beside them (one per board, not written to the library). ``--joint`` lists several boards with their
tests (:mod:`pcbdyn.problems.joint`), calibrated in one stacked problem. Each family's run is recorded
in DIR/FAMILY.toml (started from the entry the library search path finds when DIR has none) and
pooled with the runs already there (:mod:`pcbdyn.components.records`); a run more than 3 standard
deviations from the others is flagged, not averaged in.

JSON: ``families`` = {FAMILY: {``equivalent_thickness_m``, ``std_m`` (the library's value after this run),
``before_m`` (the value this run started from), ``n_calibrations``, ``flagged`` (this run), ``run_m``,
``run_std_m`` (this run's own estimate), ``run_std_mesh_m`` (the part of it the mesh makes), ``reason``,
``file``}}, ``before``/``after``
(``max_freq_error_pct``, per configuration), ``library`` (the folder written), ``with`` (the other
parameters), ``method``, ``solver``, ``noise``, ``boards``, ``tests``.
"""

from __future__ import annotations

import math
from pathlib import Path

import click

from .common import (checked_outputs, done, echo_verdict, fail, input_errors, library_option, parse_extra, parse_noise,
                     step, test_arguments, units_option)


def names(text) -> list | None:
    """'PGA, CQFP' -> ['PGA', 'CQFP']; None when not given."""
    return [n.strip() for n in text.split(",") if n.strip()] if text else None


@click.command("calibrate")
@test_arguments(board_required=False)
@click.option("--joint", "joint_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="calibration file listing several boards with their tests, calibrated together")
@click.option("--families", default=None, help="comma-separated part families (default: every family whose parts "
                                                "use the equivalent_thickness model)")
@click.option("--with", "with_", default=None,
              help="comma-separated quantities fitted beside the families, e.g. board.E (a target or a "
                   "[[parameters]] name; one per board)")
@click.option("--method", type=click.Choice(["freq", "qms", "fbm"]), default="freq", show_default=True)
@click.option("--solver", type=click.Choice(["ls", "tls", "bayes", "bounded"]), default="bounded", show_default=True)
@click.option("--noise", default=None, help="test noise in percent as uniform bounds, e.g. 'f=0.2,shape=2' "
                                            "(default: estimated from the fit's residual)")
@click.option("--max-iter", type=click.IntRange(min=1), default=20, show_default=True)
@click.option("--tol", "tol_pct", type=float, default=0.05, show_default=True,
              help="stop when the max frequency error is below this percentage (eq. 7.2)")
@click.option("--mesh-size", default=None, help="override the boards' mesh_size, e.g. '5 mm'")
@click.option("--mesh-error/--no-mesh-error", default=True, show_default=True,
              help="count what the mesh does to each mode (solved again twice as fine) in the standard deviation")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write the families, before/after and the library written as JSON ('-': standard output)")
@checked_outputs(folders=())
@library_option(required=True, keep=True)
@units_option
def command(board_toml, test_uff, configs, freq_csv, joint_toml, families, with_, method, solver, noise, max_iter,
            tol_pct, mesh_size, mesh_error, json_path, library):
    """Calibrate part families' equivalent thicknesses from modal tests into a component library."""
    from ..problems.calibration import calibrate, calibration_problem
    from ..problems.calibration_library import check_library, max_error, write_library
    from ..problems.joint import load_board_tests, read_joint
    from ..report import calibration_report as rep
    from ..report.files import write_json
    from ..units import to_si

    if board_toml is None and joint_toml is None:
        fail("give BOARD_TOML and its test (TEST_UFF, or --frequencies FILE.csv), or --joint calibration.toml")
    if board_toml is not None and (test_uff is None) == (freq_csv is None):
        fail(f"{board_toml.name}: give its test TEST_UFF (and NAME=FILE for other configurations) or "
             "--frequencies FILE.csv, one of them")
    if freq_csv is not None and method != "freq":
        fail("--frequencies holds no shapes: use --method freq")
    extras = parse_extra(configs)
    f_pct, shape_pct = parse_noise(noise)
    with input_errors():
        t0 = step("reading the boards and their tests")
        items = [] if board_toml is None else [load_board_tests(board_toml, test_uff, extras, freq_csv)]
        items += [] if joint_toml is None else read_joint(joint_toml)
        ms = to_si(mesh_size, "mm", "--mesh-size") if mesh_size else None
        cal = calibration_problem(items, names(families), names(with_) or (), ms)
        check_library(cal, library)
        done(t0)
        t0 = step(f"calibrating {', '.join(cal.families)} on {len(items)} board(s) with {method}/{solver}")
        cal = calibrate(cal, method, solver, (f_pct, shape_pct), mesh_error, max_iter=max_iter, tol_freq_pct=tol_pct,
                        tol_param_pct=0.01, progress=lambda msg: click.echo(f"    {msg}", err=True))
        done(t0)
        what = {"status": cal.fit.status, "details": cal.fit.details, "warnings": cal.fit.warnings}
        t0 = step(f"writing the library {library}")
        fams = write_library(cal, library)
        done(t0)
    click.echo(f"\n{rep.headline(cal, what['status'])}")
    echo_verdict(what)
    click.echo(rep.format_families(fams))
    if cal.problem.names[len(cal.families):]:
        click.echo("\n" + rep.format_with(cal))
    click.echo("\n" + rep.format_correlation(cal.before, cal.after))
    for fam, d in fams.items():
        if d["flagged"]:
            click.echo(f"warning: {fam}: this run is flagged, not pooled: {d['reason']}", err=True)
    click.echo(f"\nlibrary written: {library} ({', '.join(f'{f}.toml' for f in fams)})", err=True)
    if json_path is not None:
        def summary(states):
            v = max_error(states)
            return {"max_freq_error_pct": v if math.isfinite(v) else None, "configurations": states}

        write_json(json_path, {
            "families": fams, "before": summary(cal.before), "after": summary(cal.after), "library": str(library),
            "with": rep.with_rows(cal), "method": method, "solver": solver, "noise": cal.noise,
            "status": what["status"], "details": what["details"], "warnings": what["warnings"],
            "verdict": cal.fit.verdict,
            "iterations": cal.result.iterations,
            "converged": bool(cal.result.converged), "reason": cal.result.reason,
            "boards": [str(it.structure.path) for it in cal.items],
            "tests": [{"board": it.structure.path.name, "configuration": c or "base", "file": str(p)}
                      for it in cal.items for c, p in it.files],
            "mesh_step_pct": [[100.0 * float(v) for v in u] for u in cal.mesh_steps],
        })
