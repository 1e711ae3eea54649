"""``pcbdyn export board.toml --nastran model.bdf``: the board's FE model as it is solved, as a
Nastran SOL 103 deck (see :mod:`pcbdyn.exchange.nastran` for the cards), optionally with the
values of an updated board (``--updated board.updated.toml`` from ``pcbdyn update``)."""

from __future__ import annotations

from pathlib import Path

import click

from ..domain import MAX_MODES
from .common import checked_outputs, done, fail, library_option, step


def changed_quantities(base, updated, base_name: str, updated_name: str) -> dict:
    """{quantity: (base value, updated value)} [SI] of two models of one board; a BoardError when
    the updated file describes another board (other quantities or another mesh)."""
    from ..board import BoardError

    if set(base.quantities) != set(updated.quantities) or base.model.n_nodes != updated.model.n_nodes:
        only = sorted(set(base.quantities) ^ set(updated.quantities))
        raise BoardError(f"{updated_name} is not an update of {base_name}: "
                         + (f"quantities {', '.join(only[:6])} are in one only" if only else
                            f"its mesh has {updated.model.n_nodes} nodes, not {base.model.n_nodes}")
                         + "; give the board.updated.toml that 'pcbdyn update' wrote for this board")
    return {k: (float(v), float(updated.quantities[k])) for k, v in base.quantities.items()
            if abs(float(updated.quantities[k]) - float(v)) > 1e-12 * max(abs(float(v)), 1e-300)}


@click.command("export")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--nastran", "bdf", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Nastran bulk data deck to write (SOL 103, SI units)")
@click.option("--updated", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="board.updated.toml from 'pcbdyn update': export its values (same board, same mesh)")
@click.option("--config", default=None, help="configuration name from [[configurations]]")
@click.option("--modes", "n_modes", type=click.IntRange(1, MAX_MODES), default=None,
              help="elastic modes asked for on EIGRL, which adds a free board's rigid-body modes (default: [analysis] "
                   "modes of the board)")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write the card counts, mass, changed values and notes as JSON")
@checked_outputs(folders=(), files=("json_path", "bdf"))
@library_option()
def command(board_toml, bdf, updated, config, n_modes, json_path):
    """Write the board's FE model as a Nastran deck (GRID, CQUAD4/CTRIA3, PSHELL, CBAR, CONM2,
    springs, SPC1, MPC, EIGRL)."""
    from ..board import BoardError, build_model, load_board
    from ..exchange import write_nastran
    from ..fe import ModelError
    from ..report.files import write_json

    try:
        board = load_board(board_toml)
        t0 = step(f"[{config or 'base'}] meshing and building the model of {board_toml.name}")
        bm = build_model(board, config)
        changed = {}
        if updated is not None:
            bm_updated = build_model(load_board(updated), config)
            changed = changed_quantities(bm, bm_updated, board_toml.name, updated.name)
            bm = bm_updated
        done(t0)
        source = updated or board_toml
        n = n_modes or bm.board.analysis.modes
        header = f"{bm.board.name} [{config or 'base'}] from {source.name}" + "".join(
            f"\n  {k}: {a:.6g} -> {b:.6g} (SI, updated)" for k, (a, b) in changed.items())
        t0 = step(f"writing {bdf}")
        deck = write_nastran(bdf, bm.model, n, bm.board.analysis.f_max, title=bm.board.name, header=header)
        done(t0)
        mass = bm.mass()
    except (BoardError, ModelError) as exc:
        fail(str(exc))
    click.echo(f"\n{bm.board.name} [{config or 'base'}]: {mass * 1e3:.3f} g, {bm.model.n_nodes} nodes "
               f"(+{deck.extra_grids} extra grids), EIGRL {n + deck.rigid_modes} modes ({n} elastic"
               + (f" and the {deck.rigid_modes} rigid-body modes Nastran counts)" if deck.rigid_modes else ")"))
    click.echo("  ".join(f"{k} {v}" for k, v in sorted(deck.counts.items())))
    for k, (a, b) in changed.items():
        click.echo(f"updated: {k} {a:.6g} -> {b:.6g} (SI)")
    for note in deck.notes:
        click.echo(f"note: {note}")
    click.echo(f"written {bdf}", err=True)
    if json_path is not None:
        write_json(json_path, {
            "board": bm.board.name, "configuration": config or "base", "source": str(source), "nastran": str(bdf),
            "cards": dict(sorted(deck.counts.items())), "mass_kg": mass, "modes": n,
            "eigrl_nd": n + deck.rigid_modes,
            "sets": deck.sets, "extra_grids": deck.extra_grids, "notes": deck.notes,
            "updated": {k: {"from": a, "to": b} for k, (a, b) in changed.items()},
        })
