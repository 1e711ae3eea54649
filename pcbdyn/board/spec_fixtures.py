"""board.toml readers of the supports and masses: ``[[fixtures]]`` (free, clamped/hinged edges,
wedge-lock guides, standoffs, point and edge springs) and ``[[masses]]``."""

from __future__ import annotations

import numpy as np

from ..units import shown
from .entries import FIXTURE_TYPES, Fixture, PointMass
from .geometry import circle, on_line
from ..fixtures.supports import support_line
from .spec_effects import read_segment


def _edge(r, text, where, outline):
    s = str(text).replace(" ", "")
    if not isinstance(text, str) or len(s) < 3 or s[0] not in "xy" or s[1] != "=":
        r.fail(where, f"{shown(text)} is not an edge; write e.g. \"x=0\" or \"y=178 mm\"")
    axis = "xy".index(s[0])
    val = s[2:]
    value = 0.0 if val in ("0", "0.0") else r.q(text.split("=", 1)[1].strip(), "mm", where)
    ext = outline.edge_extent(axis, value)
    if ext is None:
        lo, hi = outline.bbox
        r.fail(where, f"'{text}' is not an edge of the outline (the board spans x = 0..{hi[0] * 1e3:g} mm, "
                      f"y = 0..{hi[1] * 1e3:g} mm); use a line the outline runs along")
    return axis, value


def _point_on_board(r, board, f, where, what: str):
    """A fixture's ``at`` point, required and on the board."""
    if "at" not in f:
        r.fail(f"{where}.at", f"missing; a {what} needs at = [\"x mm\", \"y mm\"]")
    at = r.point(f["at"], f"{where}.at")
    if not board.outline.contains(at)[0]:
        r.fail(f"{where}.at", f"{f['at']} is not on the board; move the {what} inside the outline")
    return at


def read_fixture(r, f, where, board, i) -> Fixture:
    r.table(f, where, ["name", "type", "edge", "width", "k_rot", "at", "k", "diameter", "from", "to"],
            required=["type"])
    typ = r.choice(f["type"], f"{where}.type", FIXTURE_TYPES, "fixture type")
    name = r.name("fixtures", f, i, where)
    if board.fixture(name) is not None:
        r.fail(f"{where}.name", f"'{name}' is used by another fixture; names must be unique")
    fx = Fixture(name, typ)
    if typ in ("clamped_edge", "hinged_edge", "wedge_lock"):
        if "edge" not in f:
            r.fail(f"{where}.edge", "missing; add edge = \"x=0\" (or \"y=178 mm\", ...)")
        fx.edge = _edge(r, f["edge"], f"{where}.edge", board.outline)
        fx.width = r.q(f["width"], "mm", f"{where}.width", nonneg=True) if "width" in f else 0.0
        if typ == "wedge_lock":
            if "k_rot" not in f:
                r.fail(f"{where}.k_rot", "missing; add k_rot = \"1e4 N*m/rad/m\" (or \"clamped\" / \"hinged\")")
            k = f["k_rot"]
            fx.k_rot = k if isinstance(k, str) and k in ("clamped", "hinged") else r.q(k, "N*m/rad/m", f"{where}.k_rot", nonneg=True)
    elif typ == "standoff":
        fx.at = _point_on_board(r, board, f, where, "standoff")
        k = f.get("k", "rigid")
        fx.k = "rigid" if isinstance(k, str) and k == "rigid" else r.q(k, "N/m", f"{where}.k", positive=True)
        fx.diameter = r.q(f.get("diameter", "6 mm"), "mm", f"{where}.diameter", positive=True)
        if not board.outline.contains(circle(fx.at, fx.diameter)).all():
            r.fail(f"{where}.diameter", "the standoff's pad reaches off the board; move it or make it smaller")
        for other in board.fixtures:
            gap = float(np.linalg.norm(np.subtract(fx.at, other.at))) if other.type == "standoff" else np.inf
            if gap < 0.5 * (fx.diameter + other.diameter):
                r.fail(f"{where}.at", f"the standoff's pad overlaps that of standoff '{other.name}' (centres "
                                      f"{gap * 1e3:.3g} mm apart, pads {fx.diameter * 1e3:.3g} and "
                                      f"{other.diameter * 1e3:.3g} mm): move them apart, make the pads smaller "
                                      "or declare one standoff")
    elif typ == "point_spring":
        fx.at = _point_on_board(r, board, f, where, "point spring")
        if "k" not in f:
            r.fail(f"{where}.k", "missing; add k = \"1e5 N/m\" (stiffness to ground in z)")
        fx.k = r.q(f["k"], "N/m", f"{where}.k", positive=True)
    elif typ == "edge_spring":
        fx.segment = read_segment(r, f, where, board)
        if "k_rot" not in f:
            r.fail(f"{where}.k_rot", "missing; add k_rot = \"1e3 N*m/rad/m\" (rotation about the segment)")
        fx.k_rot = r.q(f["k_rot"], "N*m/rad/m", f"{where}.k_rot", positive=True)
    uses = {"free": (), "clamped_edge": ("edge", "width"), "hinged_edge": ("edge", "width"),
            "wedge_lock": ("edge", "width", "k_rot"), "standoff": ("at", "k", "diameter"),
            "point_spring": ("at", "k"), "edge_spring": ("from", "to", "k_rot")}[typ]
    for key in ("edge", "width", "k_rot", "at", "k", "diameter", "from", "to"):
        if key in f and key not in uses:
            r.fail(f"{where}.{key}", f"a {typ} fixture has no {key}; remove it")
    return fx


def read_mass(r, m, where, board, index) -> PointMass:
    """A point mass; ``inertia`` J is its rotary inertia about the x and y axes (Ixx = Iyy = J,
    Izz = 0), so mass = "0 g" with an inertia > 0 declares a rotary inertia alone."""
    r.table(m, where, ["name", "at", "mass", "inertia"], required=["at", "mass"])
    pm = PointMass(r.name("masses", m, index, where), r.point(m["at"], f"{where}.at"),
                   r.q(m["mass"], "g", f"{where}.mass", nonneg=True),
                   r.q(m.get("inertia", "0 kg*m^2"), "kg*m^2", f"{where}.inertia", nonneg=True))
    if not pm.mass > 0 and not pm.inertia > 0:
        r.fail(f"{where}.mass", f"must be positive, got {m['mass']!r} (a zero mass needs an inertia > 0)")
    if not board.outline.contains(pm.at)[0]:
        r.fail(f"{where}.at", f"{m['at']} is not on the board; move the mass inside the outline")
    return pm


def check_edge_springs(r, board):
    """An edge spring's segment lies on one straight piece of the outline (or a hole's) or on the
    support line of an edge fixture."""
    pieces = []
    for ring in [board.outline.vertices, *board.outline.holes]:
        pieces += list(zip(ring, np.roll(ring, -1, axis=0)))
    for f in board.fixtures:
        if f.edge is not None:
            axis, v, lo, hi = support_line(board.outline, f)
            a, b = np.zeros(2), np.zeros(2)
            a[axis] = b[axis] = v
            a[1 - axis], b[1 - axis] = lo, hi
            pieces.append((a, b))
    for i, f in enumerate(board.fixtures):
        if f.type == "edge_spring" and not any(on_line(f.segment, a, b) for a, b in pieces):
            (x0, y0), (x1, y1) = f.segment
            r.fail(f"fixtures[{i}].from", f"the segment ({x0 * 1e3:g}, {y0 * 1e3:g}) -> ({x1 * 1e3:g}, "
                                          f"{y1 * 1e3:g}) mm does not lie on the board outline or on an edge "
                                          "fixture's support line; move its ends onto one straight edge")
