"""Planar geometry of board entries: footprints overlapping, segments on the board or on a line."""

from __future__ import annotations

import numpy as np

from .entries import GEOM_TOL, MIN_SEGMENT


def polygon_problem(v) -> str | None:
    """Why the closed polygon ``v`` (m, 2) [m] cannot be meshed (None when it can): corners closer than
    :data:`MIN_SEGMENT` (a repeated vertex), or sides that cross or touch."""
    from shapely import validation
    from shapely.geometry import Polygon

    v = np.asarray(v, dtype=float)
    side = np.linalg.norm(np.roll(v, -1, axis=0) - v, axis=1)
    if (side < MIN_SEGMENT).any():
        k = int(np.argmax(side < MIN_SEGMENT))
        return (f"corners {k} and {(k + 1) % len(v)} are {side[k] * 1e3:g} mm apart (a repeated point?); "
                f"corners must be at least {MIN_SEGMENT * 1e3:g} mm apart")
    poly = Polygon(v)
    if not poly.is_valid:
        return f"its sides cross or touch ({validation.explain_validity(poly)}); list the corners in order around it"
    return None


def hole_problem(outline_v, holes, hole) -> str | None:
    """Why polygon ``hole`` cannot be cut from the board ``outline_v`` beside the ``holes`` before it
    (None when it can): it must lie inside, clear of the edge and of the other holes."""
    from shapely.geometry import Polygon

    h = Polygon(hole)
    board = Polygon(outline_v)
    if not board.contains(h) or h.exterior.distance(board.exterior) < MIN_SEGMENT:
        return "is not inside the outline (clear of its edge); move it or make it smaller"
    for k, other in enumerate(holes):
        if h.distance(Polygon(other)) < MIN_SEGMENT:
            return f"overlaps or touches hole {k}; move one of them or merge them into one polygon"
    return None


def polys_overlap(p, q) -> bool:
    """Convex polygons overlap with positive area (separating-axis test, touching allowed)."""
    for poly in (p, q):
        e = np.roll(poly, -1, axis=0) - poly
        normals = np.c_[-e[:, 1], e[:, 0]]
        for n in normals:
            a, b = p @ n, q @ n
            scale = np.linalg.norm(n)
            if a.max() <= b.min() + GEOM_TOL * scale or b.max() <= a.min() + GEOM_TOL * scale:
                return False
    return True


def on_board(outline, p0, p1) -> bool:
    """The straight segment p0 -> p1 lies on the board (sampled every 0.1 mm at most)."""
    p0, p1 = np.asarray(p0), np.asarray(p1)
    n = max(51, int(np.linalg.norm(p1 - p0) / 1e-4) + 1)
    s = np.linspace(0.0, 1.0, n)[:, None]
    return bool(outline.contains(p0 + s * (p1 - p0)).all())


def on_line(seg, a, b, tol=GEOM_TOL) -> bool:
    """Both ends of ``seg`` lie on the straight piece a -> b."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = b - a
    L = float(np.linalg.norm(d))
    for p in seg:
        rel = np.asarray(p) - a
        if abs(rel[0] * d[1] - rel[1] * d[0]) / L > tol or not -tol <= rel @ d / L <= L + tol:
            return False
    return True


def circle(centre, diameter, n=12) -> np.ndarray:
    ang = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.asarray(centre) + 0.5 * diameter * np.c_[np.cos(ang), np.sin(ang)]
