"""board.toml readers of the ``[board]`` table: outline (and holes) in the board frame, and the plate
(an isotropic material with a thickness, or a stack-up reduced by lamination theory)."""

from __future__ import annotations

import numpy as np
from matplotlib.path import Path as PolyPath

from ..fe import ShellProperty
from .entries import GEOM_TOL, Outline
from .laminate import MATERIALS, LaminateProperty, Layer, Material


def read_outline(r, o) -> Outline:
    r.table(o, "board.outline", ["width", "height", "polygon", "holes"])
    if "polygon" in o:
        pts = o["polygon"]
        if not isinstance(pts, list) or len(pts) < 3:
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
    area2 = np.dot(v[:, 0], np.roll(v[:, 1], -1)) - np.dot(v[:, 1], np.roll(v[:, 0], -1))
    if abs(area2) < 1e-12:
        r.fail("board.outline.polygon", "encloses no area")
    if area2 < 0:
        v = v[::-1]
    holes = []
    for i, h in enumerate(o.get("holes", [])):
        where = f"board.outline.holes[{i}]"
        r.table(h, where, ["polygon", "at", "diameter", "size"])
        if "polygon" in h:
            hv = np.array([r.point(p, f"{where}.polygon[{j}]") for j, p in enumerate(h["polygon"])]) - lo
        elif "at" in h and "diameter" in h:
            c = np.array(r.point(h["at"], f"{where}.at")) - lo
            d = r.q(h["diameter"], "mm", f"{where}.diameter", positive=True)
            ang = np.linspace(0, 2 * np.pi, 16, endpoint=False)
            hv = c + 0.5 * d * np.c_[np.cos(ang), np.sin(ang)]
        elif "at" in h and "size" in h:
            c = np.array(r.point(h["at"], f"{where}.at")) - lo
            a, b = (r.q(s, "mm", f"{where}.size", positive=True) for s in h["size"])
            hv = c + np.array([[-a, -b], [a, -b], [a, b], [-a, b]]) / 2
        else:
            r.fail(where, "give polygon, or at with diameter (round) or size (rectangular)")
        if not PolyPath(v).contains_points(hv, radius=-GEOM_TOL).all():
            r.fail(where, "is not inside the outline; move it or make it smaller")
        holes.append(hv)
    return Outline(v, holes, rect and not holes)


def read_plate(r, b):
    if "thickness" in b and "stackup" in b:
        r.fail("board.thickness", "give either thickness with material, or stackup (its layers set the thickness)")
    if "stackup" in b:
        layers = []
        for i, L in enumerate(b["stackup"]):
            where = f"board.stackup[{i}]"
            r.table(L, where, ["thickness", "material", "fill", "filler"], required=["thickness", "material"])
            mats = {}
            for key in ("material", "filler"):
                name = L.get(key, "FR4")
                if isinstance(name, dict):
                    mats[key] = read_material(r, name, f"{where}.{key}")
                elif name in MATERIALS:
                    mats[key] = Material(*MATERIALS[name])
                else:
                    r.fail(f"{where}.{key}", f"unknown material '{name}'; use one of {', '.join(MATERIALS)} "
                                             "or a table { E = ..., nu = ..., rho = ... }")
            fill = L.get("fill", 1.0)
            if isinstance(fill, bool) or not isinstance(fill, (int, float)) or not 0 <= fill <= 1:
                r.fail(f"{where}.fill", f"must be a number from 0 to 1, got {fill!r}")
            layers.append(Layer(r.q(L["thickness"], "mm", f"{where}.thickness", positive=True), mats["material"],
                                float(fill), mats["filler"]))
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
