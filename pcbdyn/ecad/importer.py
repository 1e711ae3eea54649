"""A KiCad board as a board.toml: outline and cut-outs, stack-up, the mapped footprints as
[[components]], mounting holes as commented standoff candidates, and in its header what was
left out (unmapped footprints with their count, parts off the board or overlapping another).

Parts are placed largest first; a part whose body leaves the outline is clipped to it when it is
square to the axes (a connector over the edge keeps its mass on the board's part of it), else
kept out, as is a part overlapping a hole or a placed part (pcbdyn's footprints may not overlap,
whatever side they are on): each is listed with the reason, never moved.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .board_toml import board_toml, mm
from .kicad import KicadError, read_kicad
from .packages import read_map

#: KiCad dielectric material names -> pcbdyn's (lower-case keys); prepreg layers of FR4 are "prepreg"
MATERIAL_NAMES = {"fr4": "FR4", "fr-4": "FR4", "polyimide": "polyimide", "pi": "polyimide"}


@dataclass
class Imported:
    text: str
    components: list  # [{"ref", "footprint", "side", ...component keys}]
    unmapped: dict  # footprint -> [refs]
    ignored: int
    standoffs: list  # [{"ref", "footprint", "at", "diameter"}]
    kept_out: list = field(default_factory=list)  # [{"ref", "footprint", "reason"}]
    notes: list = field(default_factory=list)


def _material(kind: str, name, pmap, where: str):
    kind_l = kind.lower()
    if kind_l == "copper":
        return "copper"
    if "solder mask" in kind_l:
        return "solder_mask"
    if name in pmap.materials:
        return pmap.materials[name]
    canonical = MATERIAL_NAMES.get(str(name).strip().lower())
    if canonical is None:
        raise KicadError(f"{where}: dielectric material '{name}' is not one pcbdyn knows; map it in "
                         f"{pmap.path.name} under [materials], e.g. \"{name}\" = {{ E = \"20 GPa\", nu = 0.2, "
                         "rho = \"1900 kg/m^3\" }} or \"FR4\"")
    return "prepreg" if kind_l == "prepreg" and canonical == "FR4" else canonical


def _stackup(layout, pmap, notes):
    """board.toml stack-up entries, bottom to top, or None when the file has no stack-up."""
    if not layout.stackup:
        notes.append(f"no stack-up in the file: board thickness {mm(layout.thickness)} of FR4 assumed")
        return None
    out = []
    for kind, name, t in reversed(layout.stackup):
        out.append({"thickness": mm(t), "material": _material(kind, name, pmap, f"stack-up layer {kind} ({name})")})
    if any(kind.lower() == "copper" for kind, _, _ in layout.stackup):
        notes.append("copper layers are written as full sheets (fill = 1): KiCad does not say how much copper "
                     "each layer keeps; set fill per layer")
    return out


def _rectangle(at, size, rotation):
    from shapely.geometry import Polygon

    a, b = size
    c, s = np.cos(np.radians(rotation)), np.sin(np.radians(rotation))
    local = np.array([[-a, -b], [a, -b], [a, b], [-a, b]]) / 2
    return Polygon(np.asarray(at) + local @ np.array([[c, s], [-s, c]]))


def _board_shape(layout):
    from shapely.geometry import Point, Polygon

    shape = Polygon(layout.outline)
    for h in layout.holes:
        shape = shape.difference(Point(h[1]).buffer(h[2] / 2, 64) if h[0] == "circle" else Polygon(h[1]))
    return shape


def _place(parts, layout, kept_out, notes):
    """The parts that fit, largest first: clipped to the board when square to the axes, else kept out."""
    board = _board_shape(layout)
    placed, shapes = [], []
    for p in sorted(parts, key=lambda p: -p["_size"][0] * p["_size"][1]):
        rect = _rectangle(p["_at"], p["_size"], p["_rotation"])
        if rect.area > 0 and not board.buffer(1e-9).contains(rect):
            square = abs(p["_rotation"] % 90.0) < 1e-9
            clipped = rect.intersection(board)
            if square and clipped.area > 0 and abs(clipped.envelope.area - clipped.area) < 1e-12 + 1e-9 * clipped.area:
                x0, y0, x1, y1 = clipped.bounds
                quarter = int(round(p["_rotation"] / 90.0)) % 2
                p["_at"] = (0.5 * (x0 + x1), 0.5 * (y0 + y1))
                p["_size"] = (y1 - y0, x1 - x0) if quarter else (x1 - x0, y1 - y0)
                rect = clipped
                notes.append(f"{p['ref']}: body clipped to the board's edge ({mm(p['_size'][0])} x {mm(p['_size'][1])})")
            else:
                kept_out.append({"ref": p["ref"], "footprint": p["footprint"], "reason": "off the board or over a hole"})
                continue
        other = next((q for q, s in zip(placed, shapes) if rect.intersection(s).area > 1e-12), None)
        if other is not None:
            kept_out.append({"ref": p["ref"], "footprint": p["footprint"], "reason": f"overlaps {other['ref']}"})
            continue
        placed.append(p)
        shapes.append(rect)
    return sorted(placed, key=lambda p: p["_index"])


def _unique_ref(ref: str, used: set) -> str:
    base = (ref or "PART").replace(".", "_")
    name, k = base, 1
    while name in used:
        k += 1
        name = f"{base}_{k}"
    used.add(name)
    return name


def import_kicad(pcb_path, map_path) -> Imported:
    """Read ``pcb_path`` (.kicad_pcb) with the footprint map ``map_path`` and write the board.toml text."""
    layout = read_kicad(pcb_path)
    pmap = read_map(map_path)
    notes: list = []
    try:
        stackup = _stackup(layout, pmap, notes)
    except KicadError as exc:
        raise KicadError(f"{Path(pcb_path).name}: {exc}") from None
    parts, unmapped, standoffs, kept_out, used = [], defaultdict(list), [], [], set()
    ignored = 0
    for i, fp in enumerate(layout.footprints):
        entry = pmap.lookup(fp.lib_id)
        lib, _, name = fp.lib_id.rpartition(":")
        if entry == "standoff" or (entry is None and (lib == "MountingHole" or name.startswith("MountingHole"))):
            standoffs.append({"ref": fp.ref, "footprint": fp.lib_id, "at": fp.at,
                              "diameter": fp.pad or 2.0 * fp.hole or 6e-3})
        elif entry == "ignore":
            ignored += 1
        elif entry is None:
            unmapped[fp.lib_id].append(fp.ref)
        else:
            parts.append({"ref": _unique_ref(fp.ref, used), "footprint": fp.lib_id, "side": fp.side, **entry,
                          "_at": fp.at, "_size": fp.size, "_rotation": fp.rotation, "_index": i})
    placed = _place(parts, layout, kept_out, notes)
    text = board_toml(layout, pcb_path, map_path, stackup, placed, unmapped, ignored, standoffs, kept_out, notes)
    components = [{k.lstrip("_"): v for k, v in p.items() if k != "_index"} for p in placed]
    return Imported(text, components, dict(unmapped), ignored, standoffs, kept_out, notes)
