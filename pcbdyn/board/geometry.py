"""Planar geometry of board entries: footprints overlapping, segments on the board or on a line."""

from __future__ import annotations

import numpy as np

from .entries import GEOM_TOL


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
