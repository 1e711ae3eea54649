"""``pcbdyn diagnose board.toml test.uff [c2=test2.uff ...]``: find what the model lacks (issue 7).

Fits the declared [[parameters]], tests whether the residual is noise and, when it is not, searches
the catalogue of effects (point masses and inertias, ground springs, edge stiffness, region
stiffness, stiffeners, line masses) for the fewest that explain it, estimated together with the
parameters (:func:`pcbdyn.diagnosis.pipeline.diagnose`). Prints the effects and the correlation as
given / parameters only / with the effects; writes ``<board>.diagnosed.toml`` declaring them, with the
parameters at their fitted values, next to the original, the evidence map and tables in ``--out`` (with
``--html``, a page showing the effects on the modes of the model that declares them), and JSON.
"""

from __future__ import annotations

from pathlib import Path

import click

from ..diagnosis import KINDS
from .common import (done, folder_outputs, input_errors, library_option, measured_configurations, parse_noise, result_path,
                     solve_structure, step, units_option)

#: the correlation summaries of a diagnosis (JSON: max error, mean MAC, pairs per configuration)
STATES = ("before", "parameters_only", "after")


@click.command("diagnose")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("test_uff", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("configs", nargs=-1)
@click.option("--noise", default=None,
              help="measurement noise in percent as uniform bounds (thesis eqs. 5.72-5.73), e.g. 'f=0.2,shape=2'; "
                   "default: frequencies 0.2 %, shapes estimated from the data")
@click.option("--kinds", default=None, help=f"comma-separated catalogue kinds to search (default: all): {', '.join(KINDS)}")
@click.option("--max-effects", type=click.IntRange(min=1), default=3, show_default=True)
@click.option("--mesh-size", default=None, help="element size, e.g. '5 mm' (default: the board's)")
@click.option("--quick", is_flag=True,
              help="a first look at a fraction of the cost: the mesh correction from one finer mesh (twice as fine) "
                   "instead of two, candidates on a grid half as fine (still walked to place), one trial fit per kind "
                   "in each scan instead of two, and the masses found not carried onto the finer meshes")
@click.option("--parameters-only", is_flag=True,
              help="stop after fitting the declared parameters and testing what they leave against the noise: the "
                   "error budget and the parameters-only correlation, no search for effects")
@click.option("--workers", type=click.IntRange(min=1), default=None,
              help="local processes for the finer-mesh solves, the trial fits and the configurations of each "
                   "re-solve (default: the cores; 1: this process)")
@click.option("--scheduler", default=None,
              help="a Dask scheduler address (tcp://host:8786): the finer-mesh solves and the full trial fits run "
                   "on that cluster, the rest on local processes (the findings do not depend on where they run)")
@folder_outputs("folder for the board with the effects declared, the evidence map and tables",
                "write effects, before/after and statistics as JSON", html=True,
                force="replace an earlier <board>.diagnosed.toml beside the board (default: a numbered name)")
@library_option()
@units_option
def command(board_toml, test_uff, configs, noise, kinds, max_effects, mesh_size, quick, parameters_only, workers,
            scheduler, out, force, json_path, html):
    """Find the effects a board model lacks from modal tests: TEST_UFF (with mode shapes) of the base
    configuration and NAME=FILE for each perturbed configuration of board.toml (e.g. c2=test2.uff)."""
    from ..diagnosis.pipeline import diagnose
    from ..problems import load_structure
    from ..report import diagnosis_report as rep
    from ..report.files import write_json, write_text
    from ..units import to_si

    freq_pct, shape_pct = parse_noise(noise)
    chosen = None
    if kinds:
        chosen = [k.strip() for k in kinds.split(",") if k.strip()]
        bad = [k for k in chosen if k not in KINDS]
        if bad:
            raise click.BadParameter(f"unknown kind(s) {bad}; use {', '.join(KINDS)}", param_hint="--kinds")
    with input_errors(KeyError, ValueError):  # the readers' own errors; past them a ValueError is a bug
        board = load_structure(board_toml)
        tests = measured_configurations(board, test_uff, configs)
        ms = to_si(mesh_size, "mm", "--mesh-size") if mesh_size else None
    with input_errors():
        t0 = step("diagnosing")
        record: dict = {}
        try:
            d = diagnose(board, tests, freq_pct, shape_pct, mesh_size=ms, kinds=chosen, max_effects=max_effects,
                         progress=lambda msg: click.echo(f"    {msg}", err=True), quick=quick, workers=workers,
                         scheduler=scheduler, record=record, search_effects=not parameters_only)
        except Exception as exc:
            if json_path is not None:  # a bug, or a state no model can take: keep what was computed
                write_json(json_path, {"complete": False, "error": f"{type(exc).__name__}: {exc}",
                                       **{k: rep.summary(v) if k in STATES else v for k, v in record.items()}})
            raise
        done(t0)
    click.echo(f"\n{board.name}: {d.message}\n")
    click.echo(rep.format_effects(d.effects))
    click.echo("")
    click.echo(rep.format_states(d.before, d.parameters_only, d.after))

    def findings(enriched) -> None:  # written first: pictures that fail must not lose them
        if json_path is not None:
            write_json(json_path, {
                "complete": True, "effects": d.effects, "noise_only": d.noise_only, "message": d.message,
                "before": rep.summary(d.before), "parameters_only": rep.summary(d.parameters_only),
                "after": rep.summary(d.after), "parameters": d.parameters, "statistics": d.statistics,
                "enriched_board": None if enriched is None else str(enriched),
            })

    if out is None:
        findings(_enriched(board, d, result_path(None, board_toml, "diagnosed", force)))
    else:
        from ..report.manifest import replacing

        with replacing(out, "pcbdyn diagnose") as run:  # the earlier --out stays whole until all is written
            staged = result_path(run.path, board_toml, "diagnosed")
            enriched = _enriched(board, d, staged, run.final)
            findings(enriched)
            write_text(run.path / "effects.txt", rep.format_effects(d.effects) + "\n")
            write_text(run.path / "correlation.txt", rep.format_states(d.before, d.parameters_only, d.after) + "\n")
            if d.evidence:
                rep.plot_evidence(run.path / "evidence.png", board, d.evidence, d.effects)
            if html:
                page = run.final(_page(run.path, board_toml, board, d, staged if enriched is not None else None))
                click.echo(f"page written to {page}", err=True)


def _page(folder, board_toml, board, d, enriched):
    """report.html in ``folder``: the effects on the modes of the board that declares them (``enriched``,
    its file; the board as given when there is none or it cannot be read)."""
    from ..domain import StructureError
    from ..problems import load_structure
    from ..report import diagnosis_report as rep

    shown = board
    if enriched is not None:
        try:
            shown = load_structure(enriched)
        except StructureError as exc:
            click.echo(f"note: the page shows the model as given: {exc}", err=True)
    bm, modes, _, _ = solve_structure(shown, None)
    title = board.name + (" with the effects" if shown is not board else "")
    evidence = folder / "evidence.png"
    return rep.html_page(folder, board_toml, board, d, (title, bm, modes, shown.outlines(None)),
                         evidence if evidence.is_file() else None)


def _enriched(board, d, path, final=lambda p: p):
    """The board with the effects found declared and the parameters at their fitted values, written to
    ``path`` (None when no effect was found, or when it cannot be written: said why); returns where it ends
    up (``final`` of the path written)."""
    from ..domain import StructureError
    from ..report import diagnosis_report as rep

    if not d.effects:
        return None
    try:
        values = {name: v["final"] for name, v in d.parameters.items()}
        enriched = final(board.write_enriched(rep.enriched_effects(d), path, values=values))
    except StructureError as exc:
        click.echo(f"\nnote: the enriched board.toml was not written: {exc}", err=True)
        return None
    click.echo(f"\nboard with the effects declared written to {enriched}", err=True)
    return enriched
