"""Cards in a housing: the ``[[cards]]`` of a box.toml (a board.toml placed in the box frame) and where
each of the card's fixtures holds it to the housing.

A card's board frame (x, y in its plane, z = x cross y) lies in the box frame with its (0, 0) at
``origin`` and its x and y axes along ``u`` and ``v``. Its fixtures hold it to the housing where they
lie on a plate or a rib, within the box's mesh size: an edge fixture (wedge-lock guide, clamped or
hinged edge) on the plate that its support line touches, a standoff on the plate face or rib top under
it. The gap is measured from the card's mid-surface minus half the card's thickness to the plate's
face (half its thickness from its mid-surface) or to the rib's top: zero when they touch. A fixture
that touches nothing is an error naming it and the gap to the nearest plate or rib.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..board import BoardError, load_board
from ..fixtures.supports import support_line
from ..inputs import MAX_NAME, MAX_TEXT
from .geometry import segment_gap

#: [-] largest |u . v| (unit vectors) of a card's axes: the board frame is Cartesian
ORTHOGONAL_TOL = 1e-6
#: most cards a box may hold
MAX_CARDS = 32
#: fixtures a housing holds (the others, point and edge springs, stay springs to the fixed frame)
HELD_TYPES = ("wedge_lock", "clamped_edge", "hinged_edge", "standoff")


@dataclass
class Card:
    """A board (:class:`pcbdyn.board.Board`) placed in the box frame: ``R`` (3, 3) has the board's
    x, y, z axes as columns, ``origin`` [m] is where its (0, 0) lies; ``reduce``: the number of
    fixed-interface modes of a Craig-Bampton reduction of the card to its interface (None: full)."""

    name: str
    board: object
    origin: np.ndarray
    R: np.ndarray
    reduce: int | None = None

    @property
    def normal(self) -> np.ndarray:
        return self.R[:, 2]

    def local(self, xyz) -> np.ndarray:
        """Box-frame points (k, 3) [m] in the board frame."""
        return (np.atleast_2d(np.asarray(xyz, float)) - self.origin) @ self.R

    def distance(self, xyz) -> np.ndarray:
        """Distance [m] of box-frame points (k, 3) from the card's mid-surface (the outline's area, holes
        included in it: a point over a hole is as far as it is off the plane)."""
        from shapely.geometry import Point, Polygon

        p = self.local(xyz)
        poly = Polygon(self.board.outline.vertices)
        off = np.array([0.0 if self.board.outline.contains(q[:2])[0] else poly.exterior.distance(Point(q[:2]))
                        for q in p])
        return np.hypot(p[:, 2], off)

    def point(self, xyz) -> np.ndarray:
        """Board-frame points (k, 2 or 3) [m] in the box frame."""
        p = np.atleast_2d(np.asarray(xyz, float))
        p = np.column_stack([p, np.zeros(len(p))]) if p.shape[1] == 2 else p
        return self.origin + p @ self.R.T


#: Craig-Bampton fixed-interface modes of ``reduce = true``
DEFAULT_REDUCTION_MODES = 40


def read_card(r, e, where, name, box_path) -> Card:
    """One ``[[cards]]`` entry: its board.toml (relative to the box file) loaded and checked."""
    r.table(e, where, ["name", "board", "origin", "u", "v", "reduce"], required=["board", "origin", "u", "v"])
    rel = r.text(e["board"], f"{where}.board", MAX_TEXT)
    path = Path(box_path).parent / rel
    if not path.is_file():
        r.fail(f"{where}.board", f"'{rel}' does not exist (looked for {path}); give the card's board.toml as a path "
                                 f"relative to {Path(box_path).name}")
    try:
        board = load_board(path)
    except BoardError as exc:
        r.fail(f"{where}.board", f"card '{name}': {exc}")
    origin = np.array(r.point(e["origin"], f"{where}.origin", 3))
    axes = []
    for key in ("u", "v"):
        vec = e[key]
        if not (isinstance(vec, list) and len(vec) == 3):
            r.fail(f"{where}.{key}", f"must be a direction [x, y, z] (numbers), e.g. [1, 0, 0], got {vec!r}")
        a = np.array([r.number(c, f"{where}.{key}[{i}]") for i, c in enumerate(vec)], float)
        if np.linalg.norm(a) < 1e-12:
            r.fail(f"{where}.{key}", "has zero length; give the board's axis as a direction in the box frame")
        axes.append(a / np.linalg.norm(a))
    if abs(axes[0] @ axes[1]) > ORTHOGONAL_TOL:
        r.fail(f"{where}.v", f"is not at right angles to u (u . v = {axes[0] @ axes[1]:.3g} for unit vectors): the "
                             "board's x and y axes are perpendicular")
    R = np.column_stack([axes[0], axes[1], np.cross(axes[0], axes[1])])
    reduce = e.get("reduce", False)
    if isinstance(reduce, bool):
        modes = DEFAULT_REDUCTION_MODES if reduce else None
    else:
        modes = r.whole(reduce, f"{where}.reduce", 1, 2000, "fixed-interface modes of the Craig-Bampton reduction "
                                                            "(or true for the default)")
    return Card(name[:MAX_NAME], board, origin, R, modes)


@dataclass
class Hold:
    """Where fixture ``fixture`` of a card touches the housing: on plate ``plate`` (name) or, for a
    standoff, on rib ``rib`` (name, or None); ``gap`` [m]."""

    fixture: object
    plate: str
    rib: str | None
    gap: float


def edge_line(card, f) -> tuple:
    """(start, end) [m] in the box frame of an edge fixture's support line."""
    axis, value, lo, hi = support_line(card.board.outline, f)
    a, b = np.zeros(2), np.zeros(2)
    a[axis] = b[axis] = value
    a[1 - axis], b[1 - axis] = lo, hi
    return tuple(card.point(np.array([a, b])))


def _rib_top(box, rib) -> tuple:
    """(start, end) [m] of the line along the top of rib ``rib``."""
    plate = box.plate(rib.plate)
    up = plate.normal * (1.0 if rib.side == "+n" else -1.0) * (0.5 * plate.thickness + rib.height)
    return plate.point(*rib.start) + up, plate.point(*rib.end) + up


def _candidates(box, card, f) -> list:
    """[(gap [m], plate name, rib name or None)] of every plate (and, for a standoff, rib) of the box."""
    half = 0.5 * card.board.thickness
    if f.type == "standoff":
        p = card.point(f.at)[0]
        out = [(float(pl.distance(p)[0]) - 0.5 * pl.thickness - half, pl.name, None) for pl in box.plates]
        out += [(segment_gap(p, p, *_rib_top(box, r)) - half, r.plate, r.name) for r in box.ribs]
        return out
    a, b = edge_line(card, f)
    return [(float(pl.distance(np.array([a, b])).max()) - 0.5 * pl.thickness, pl.name, None) for pl in box.plates]


def holds(r, box, card, where) -> list:
    """The :class:`Hold` of every fixture of ``card`` the housing holds; an error (``r``: the box's
    reader) naming a fixture that touches nothing, with the gap to the nearest plate or rib."""
    out = []
    for f in card.board.fixtures:
        if f.type not in HELD_TYPES:
            continue
        gap, plate, rib = min(_candidates(box, card, f), key=lambda c: c[0])
        if gap > box.mesh_size:
            near = f"rib '{rib}'" if rib else f"plate '{plate}'"
            r.fail(where, f"fixture '{f.name}' ({f.type}) of card '{card.name}' ({card.board.path.name}) touches "
                          f"nothing: the nearest, {near}, is {gap * 1e3:.4g} mm away (more than the mesh size, "
                          f"{box.mesh_size * 1e3:g} mm); move the card's origin, or change u and v, so that the "
                          "fixture lies on a plate or a rib")
        out.append(Hold(f, plate, rib, max(gap, 0.0)))
    return out
