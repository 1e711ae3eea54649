"""Where a pretest may put sensors, an exciter, suspension springs and added masses: candidate points on a
structure (a board's outline, or every plate of a box), from a CSV or a grid of a stated spacing, each
with the plate it lies on (boxes: added masses are placed by plate and lengths along its u and v) and,
on a board, the part whose footprint covers it (no accelerometer, shaker or mass sits on a part: such
points are kept in the table, flagged, and never chosen)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.path import Path as PolyPath

from ..domain import StructureError


@dataclass
class Candidates:
    """``ids``; ``xyz`` (n, 3) [m]; ``on_part``: the part under each point ('' when none); ``plate``: the
    box plate of each point (None on a board); ``ab`` (n, 2) [m]: lengths along the plate's u and v (a
    board: x, y); ``normal`` (n, 3): the surface normal (a board: +z)."""

    ids: np.ndarray
    xyz: np.ndarray
    on_part: list
    plate: list
    ab: np.ndarray
    normal: np.ndarray

    @property
    def usable(self) -> np.ndarray:
        return np.array([not p for p in self.on_part], bool)

    def __len__(self) -> int:
        return len(self.ids)


def _axis_grid(lo: float, hi: float, spacing: float) -> np.ndarray:
    """Points from lo to hi, both ends included, at most ``spacing`` apart."""
    n = max(int(np.ceil((hi - lo) / spacing - 1e-9)), 1) + 1
    return np.linspace(lo, hi, n)


def _board_flags(board, xy) -> list:
    """The reference of the part whose footprint holds each point ('' when none)."""
    out = [""] * len(xy)
    for c in board.components:
        inside = PolyPath(c.corners()).contains_points(xy, radius=1e-9) | PolyPath(c.corners()).contains_points(
            xy, radius=-1e-9)
        for i in np.flatnonzero(inside):
            out[i] = out[i] or c.ref
    return out


def _on_board(board, ids, xyz) -> Candidates:
    n = len(ids)
    return Candidates(np.asarray(ids), xyz, _board_flags(board, xyz[:, :2]), [None] * n, xyz[:, :2].copy(),
                      np.tile([0.0, 0.0, 1.0], (n, 1)))


def _on_box(box, ids, xyz) -> Candidates:
    near, _ = box.nearest_plates(xyz)
    ab = np.zeros((len(ids), 2))
    normal = np.zeros((len(ids), 3))
    for i, k in enumerate(near):
        plate = box.plates[k]
        s, t, _ = plate.coordinates(xyz[i])[0]
        la, lb = plate.lengths
        ab[i] = np.clip(s, 0.0, 1.0) * la, np.clip(t, 0.0, 1.0) * lb
        normal[i] = plate.normal
    return Candidates(np.asarray(ids), xyz, [""] * len(ids), [box.plates[k].name for k in near], ab, normal)


def is_box(structure) -> bool:
    return hasattr(structure, "plates")


def candidate_grid(structure, spacing: float) -> Candidates:
    """A grid at most ``spacing`` [m] apart: on a board over its outline's bounding box, the points on the
    board (off holes), flagged where a part covers them; on a box over every plate, edges shared by two
    plates listed once."""
    if not spacing > 0:
        raise StructureError(f"--spacing: {spacing * 1e3:g} mm is not a positive distance")
    if is_box(structure):
        pts = []
        for p in structure.plates:
            la, lb = p.lengths
            for a in _axis_grid(0.0, la, spacing):
                for b in _axis_grid(0.0, lb, spacing):
                    pts.append(p.point(a, b))
        xyz = np.array(pts)
        _, first = np.unique(np.round(xyz, 9), axis=0, return_index=True)
        xyz = xyz[np.sort(first)]
        return _on_box(structure, np.arange(1, len(xyz) + 1), xyz)
    lo, hi = structure.outline.bbox
    X, Y = np.meshgrid(_axis_grid(lo[0], hi[0], spacing), _axis_grid(lo[1], hi[1], spacing))
    xy = np.column_stack([X.ravel(), Y.ravel()])
    xy = xy[structure.outline.contains(xy, tol=1e-9)]
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    return _on_board(structure, np.arange(1, len(xyz) + 1), xyz)


def read_candidates(structure, path) -> Candidates:
    """The points of a CSV (``point,x [mm],y [mm][,z [mm]]``; its directions are not used: the pretest
    chooses them) checked to lie on the structure; a point of the user's list is never flagged."""
    from ..testdata import read_points_csv

    points, _ = read_points_csv(path)
    structure.check_points(points, path)
    make = _on_box if is_box(structure) else _on_board
    cand = make(structure, points.ids, np.asarray(points.xyz, float))
    cand.on_part = [""] * len(cand)
    return cand

