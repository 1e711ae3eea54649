"""board.toml readers of the ``[board]`` table: outline (and holes) in the board frame, and the plate
(an isotropic material with a thickness, or a stack-up reduced by lamination theory)."""

from __future__ import annotations

import numpy as np

from ..fe import ShellProperty
from ..units import shown
from .entries import MIN_SPAN, Outline
from .geometry import hole_problem, polygon_problem
from .laminate import MATERIALS, LaminateProperty, Layer, Material


def read_outline(r, o) -> Outline:
    r.table(o, "board.outline", ["width", "height", "polygon", "holes"])
    if "polygon" in o:
        pts = r.list(o, "polygon", "board.outline.polygon")
        if len(pts) < 3:
            r.fail("board.outline.polygon", "needs at least three points [[\"x mm\", \"y mm\"], ...]")
        v = np.array([r.point(p, f"board.outline.polygon[{i}]") for i, p in enumerate(pts)])
        rect = False
    elif "width" in o and "height" in o:
        w = r.q(o["width"], "mm", "board.outline.width", positive=True)
        h = r.q(o["height"], "mm", "board.outline.height", positive=True)
        v = np.array([[0, 0], [w, 0], [w, h], [0, h]], dtype=float)
        rect = True
    else:
        r.fail("board.outline", "give width and height, or polygon = [[\"x mm\", \"y mm\"], ...]")
    lo = v.min(axis=0)
    v = v - lo
    where = "board.outline.polygon" if "polygon" in o else "board.outline"
    if float(np.min(v.max(axis=0))) < MIN_SPAN:
        r.fail(where, f"spans {float(np.min(v.max(axis=0))) * 1e3:g} mm across; a board spans at least "
                      f"{MIN_SPAN * 1e3:g} mm (are the units right?)")
    if (why := polygon_problem(v)) is not None:
        r.fail(where, why)
    area2 = np.dot(v[:, 0], np.roll(v[:, 1], -1)) - np.dot(v[:, 1], np.roll(v[:, 0], -1))
    if area2 < 0:
        v = v[::-1]
    holes = []
    for i, h in enumerate(r.list(o, "holes", "board.outline.holes")):
        where = f"board.outline.holes[{i}]"
        r.table(h, where, ["polygon", "at", "diameter", "size"])
        if "polygon" in h:
            hp = r.list(h, "polygon", f"{where}.polygon")
            if len(hp) < 3:
                r.fail(f"{where}.polygon", "needs at least three points [[\"x mm\", \"y mm\"], ...]")
            hv = np.array([r.point(p, f"{where}.polygon[{j}]") for j, p in enumerate(hp)]) - lo
        elif "at" in h and "diameter" in h:
            c = np.array(r.point(h["at"], f"{where}.at")) - lo
            d = r.q(h["diameter"], "mm", f"{where}.diameter", positive=True)
            ang = np.linspace(0, 2 * np.pi, 16, endpoint=False)
            hv = c + 0.5 * d * np.c_[np.cos(ang), np.sin(ang)]
        elif "at" in h and "size" in h:
            c = np.array(r.point(h["at"], f"{where}.at")) - lo
            if not (isinstance(h["size"], list) and len(h["size"]) == 2):
                r.fail(f"{where}.size", "must be two lengths, e.g. [\"10 mm\", \"5 mm\"]")
            a, b = (r.q(s, "mm", f"{where}.size[{k}]", positive=True) for k, s in enumerate(h["size"]))
            hv = c + np.array([[-a, -b], [a, -b], [a, b], [-a, b]]) / 2
        else:
            r.fail(where, "give polygon, or at with diameter (round) or size (rectangular)")
        if (why := polygon_problem(hv) or hole_problem(v, holes, hv)) is not None:
            r.fail(where, why)
        holes.append(hv)
    return Outline(v, holes, rect and not holes)


def read_plate(r, b):
    if "thickness" in b and "stackup" in b:
        r.fail("board.thickness", "give either thickness with material, or stackup (its layers set the thickness)")
    if "stackup" in b:
        layers = []
        for i, L in enumerate(r.list(b, "stackup", "board.stackup")):
            where = f"board.stackup[{i}]"
            r.table(L, where, ["thickness", "material", "fill", "filler"], required=["thickness", "material"])
            mats = {}
            for key in ("material", "filler"):
                name = L.get(key, "FR4")
                if isinstance(name, dict):
                    mats[key] = read_material(r, name, f"{where}.{key}")
                elif isinstance(name, str) and name in MATERIALS:
                    mats[key] = Material(*MATERIALS[name])
                else:
                    r.fail(f"{where}.{key}", f"unknown material {shown(name)}; use one of {', '.join(MATERIALS)} "
                                             "or a table { E = ..., nu = ..., rho = ... }")
            fill = r.number_in(L.get("fill", 1.0), f"{where}.fill", 0, 1, "the area fraction of material, the rest filler")
            layers.append(Layer(r.q(L["thickness"], "mm", f"{where}.thickness", positive=True), mats["material"],
                                fill, mats["filler"]))
        if not layers:
            r.fail("board.stackup", "is empty; list the layers bottom to top")
        return LaminateProperty(tuple(layers)), None
    if "thickness" not in b:
        r.fail("board.thickness", "missing; add thickness = \"1.6 mm\" (or a stackup)")
    if "material" not in b:
        r.fail("board.material", "missing; add material = { E = \"26 GPa\", nu = 0.3, rho = \"2640 kg/m^3\" }")
    t = r.q(b["thickness"], "mm", "board.thickness", positive=True)
    m = read_material(r, b["material"], "board.material")
    return ShellProperty(m.E, m.nu, m.rho, t), m


def read_material(r, m, where) -> Material:
    r.table(m, where, ["E", "nu", "rho"], required=["E", "nu", "rho"])
    return Material(r.q(m["E"], "Pa", f"{where}.E", positive=True), r.number(m["nu"], f"{where}.nu", -1.0, 0.5),
                    r.q(m["rho"], "kg/m^3", f"{where}.rho", positive=True))
