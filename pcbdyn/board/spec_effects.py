"""board.toml readers of the effect entries a diagnosis can declare: ``[[line_masses]]``,
``[[stiffeners]]`` and ``[[regions]]`` (and the segments edge springs share with line masses)."""

from __future__ import annotations

import math

import numpy as np

from .entries import MIN_SEGMENT, LineMass, Region, RibSection, Stiffener
from .geometry import on_board, polygon_problem


def entry_name(r, collection: str, e: dict, where: str) -> str:
    """The name of entry ``where`` (e.g. ``stiffeners[2]``) of ``collection`` (:meth:`pcbdyn.inputs.Reader.name`)."""
    return r.name(collection, e, int(where.rsplit("[", 1)[1].rstrip("]")), where)


def read_segment(r, e, where, board):
    """((x0, y0), (x1, y1)) [m] from ``from`` and ``to``, on the board and long enough."""
    for key in ("from", "to"):
        if key not in e:
            r.fail(f"{where}.{key}", f"missing; add {key} = [\"x mm\", \"y mm\"] (the segment's ends)")
    p0, p1 = r.point(e["from"], f"{where}.from"), r.point(e["to"], f"{where}.to")
    L = math.dist(p0, p1)
    if L < MIN_SEGMENT:
        r.fail(f"{where}.to", f"the segment is too short ({L * 1e3:g} mm); its ends must be at least "
                              f"{MIN_SEGMENT * 1e3:g} mm apart")
    if not on_board(board.outline, p0, p1):
        r.fail(f"{where}.to", f"the segment {e['from']} -> {e['to']} leaves the board; keep it inside the outline")
    return p0, p1


def read_line_mass(r, e, where, board) -> LineMass:
    r.table(e, where, ["name", "from", "to", "mass"], required=["from", "to", "mass"])
    name = entry_name(r, "line_masses", e, where)
    return LineMass(name, read_segment(r, e, where, board), r.q(e["mass"], "g", f"{where}.mass", positive=True))


def read_stiffener(r, e, where, board) -> Stiffener:
    r.table(e, where, ["name", "path", "EI", "section"], required=["path", "EI"])
    name = entry_name(r, "stiffeners", e, where)
    pts = r.list(e, "path", f"{where}.path")
    if len(pts) < 2:
        r.fail(f"{where}.path", "needs at least two points [[\"x mm\", \"y mm\"], ...]")
    path = tuple(r.point(p, f"{where}.path[{k}]") for k, p in enumerate(pts))
    for k, (p0, p1) in enumerate(zip(path[:-1], path[1:])):
        if math.dist(p0, p1) < MIN_SEGMENT:
            r.fail(f"{where}.path[{k + 1}]", f"is {math.dist(p0, p1) * 1e3:g} mm from the point before; pieces must "
                                             f"be at least {MIN_SEGMENT * 1e3:g} mm long")
        if not on_board(board.outline, p0, p1):
            r.fail(f"{where}.path[{k + 1}]", f"the piece {pts[k]} -> {pts[k + 1]} leaves the board; keep the "
                                             "stiffener inside the outline")
    sec = RibSection()
    if "section" in e:
        s = r.table(e["section"], f"{where}.section", ["E", "nu", "rho", "height"])
        sec = RibSection(
            r.q(s["E"], "Pa", f"{where}.section.E", positive=True) if "E" in s else sec.E,
            r.number(s["nu"], f"{where}.section.nu", -1.0, 0.5) if "nu" in s else sec.nu,
            r.q(s["rho"], "kg/m^3", f"{where}.section.rho", positive=True) if "rho" in s else sec.rho,
            r.q(s["height"], "mm", f"{where}.section.height", positive=True) if "height" in s else sec.h)
    return Stiffener(name, path, r.q(e["EI"], "N*m^2", f"{where}.EI", positive=True), sec)


def read_region(r, e, where, board) -> Region:
    r.table(e, where, ["name", "polygon", "rect", "stiffness_factor", "mass"])
    if "stiffness_factor" not in e and "mass" not in e:
        r.fail(where, "give stiffness_factor (1 leaves the stiffness unchanged), mass (spread over the region) or both")
    name = entry_name(r, "regions", e, where)
    if ("polygon" in e) == ("rect" in e):
        r.fail(where, "give polygon = [[\"x mm\", \"y mm\"], ...] or rect = [x0, y0, x1, y1] (one of them)")
    if "rect" in e:
        if not (isinstance(e["rect"], list) and len(e["rect"]) == 4):
            r.fail(f"{where}.rect", "must be [\"x0 mm\", \"y0 mm\", \"x1 mm\", \"y1 mm\"]")
        x0, y0, x1, y1 = (r.q(v, "mm", f"{where}.rect[{k}]") for k, v in enumerate(e["rect"]))
        (x0, x1), (y0, y1) = sorted((x0, x1)), sorted((y0, y1))
        if x1 - x0 < MIN_SEGMENT or y1 - y0 < MIN_SEGMENT:
            r.fail(f"{where}.rect", "has no area; give two opposite corners")
        poly = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    else:
        pts = r.list(e, "polygon", f"{where}.polygon")
        if len(pts) < 3:
            r.fail(f"{where}.polygon", "needs at least three points [[\"x mm\", \"y mm\"], ...]")
        poly = np.array([r.point(p, f"{where}.polygon[{k}]") for k, p in enumerate(pts)])
    x, y = poly[:, 0], poly[:, 1]
    if abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) < MIN_SEGMENT**2:
        r.fail(f"{where}.polygon", "has no area; give its corners in order")
    if (why := polygon_problem(poly)) is not None:
        r.fail(f"{where}.polygon", why)
    if not all(on_board(board.outline, a, b) for a, b in zip(poly, np.roll(poly, -1, axis=0))):
        r.fail(f"{where}", "the region reaches off the board (or over a hole); keep it inside the outline")
    factor = (r.number(e["stiffness_factor"], f"{where}.stiffness_factor", lo=0, note="1 leaves the stiffness unchanged")
              if "stiffness_factor" in e else 1.0)
    mass = r.q(e["mass"], "g", f"{where}.mass", nonneg=True) if "mass" in e else None
    return Region(name, poly, factor, mass)
