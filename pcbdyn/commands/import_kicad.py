"""``pcbdyn import-kicad board.kicad_pcb --packages map.toml --out board.toml``: a KiCad layout as a
board.toml (outline, cut-outs, stack-up, mapped parts, mounting holes as commented standoff
candidates; :mod:`pcbdyn.ecad`), checked by loading it back before it is kept."""

from __future__ import annotations

from pathlib import Path

import click

from .common import checked_outputs, done, fail, library_option, step


@click.command("import-kicad")
@click.argument("pcb", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--packages", "map_toml", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="footprint map: [footprints] \"Library:Footprint*\" = family name, \"ignore\" or { mass = ... }")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=Path("board.toml"), show_default=True,
              help="board.toml to write")
@click.option("--overwrite", is_flag=True, help="replace --out if it exists (it is kept otherwise)")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write what was placed, left out and found as JSON")
@checked_outputs(folders=(), files=("json_path", "out"))
@library_option()
def command(pcb, map_toml, out, overwrite, json_path):
    """Make a board.toml from a KiCad board (.kicad_pcb, KiCad 6-8)."""
    from ..atomic import atomic_path
    from ..board import BoardError, load_board
    from ..ecad import KicadError, import_kicad
    from ..report.files import write_json

    if out.exists() and not overwrite:
        raise click.BadParameter(f"{out} exists; give another --out or --overwrite to replace it", param_hint="--out")
    try:
        t0 = step(f"reading {pcb.name}")
        result = import_kicad(pcb, map_toml)
        done(t0)
        with atomic_path(out) as tmp:
            tmp.write_text(result.text)
            try:
                board = load_board(tmp)
            except BoardError as exc:
                raise BoardError(str(exc).replace(tmp.name, out.name) + f" (in the board made from {pcb.name}; "
                                 f"fix the layout or {map_toml.name}, or edit the written board.toml)") from None
    except (KicadError, BoardError) as exc:
        fail(str(exc))
    n_unmapped = sum(map(len, result.unmapped.values()))
    parts_mass = sum(c.mass for c in board.components)
    click.echo(f"\n{pcb.name} -> {out}: {len(board.components)} components ({parts_mass * 1e3:.2f} g), "
               f"{n_unmapped} unmapped footprint(s) kept out, {len(result.kept_out)} kept out by placement, "
               f"{result.ignored} ignored, {len(result.standoffs)} mounting hole(s) as standoff candidates")
    listed = [f"unmapped: {fp} x{len(refs)} ({', '.join(refs)})" for fp, refs in sorted(result.unmapped.items())]
    listed += [f"kept out: {k['ref']} ({k['footprint']}): {k['reason']}" for k in result.kept_out]
    click.echo("\n".join(listed + [f"note: {note}" for note in result.notes]))
    click.echo(f"written {out}", err=True)
    if json_path is not None:
        write_json(json_path, {
            "source": str(pcb), "board_toml": str(out), "components": len(board.components),
            "parts_mass_kg": parts_mass, "thickness_m": board.plate.t,
            "placed": [{"ref": c["ref"], "footprint": c["footprint"], "side": c["side"]} for c in result.components],
            "unmapped": [{"footprint": fp, "count": len(refs), "refs": refs} for fp, refs in sorted(result.unmapped.items())],
            "kept_out": result.kept_out, "ignored": result.ignored,
            "standoff_candidates": [{"ref": s["ref"], "footprint": s["footprint"], "at_m": list(map(float, s["at"])),
                                     "diameter_m": float(s["diameter"])} for s in result.standoffs],
            "notes": result.notes,
        })
