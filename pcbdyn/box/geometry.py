"""Where a box's plates meet: the segments two plates share (an edge of each lying on the other's edge, or
an edge of one lying in the other's face), the gap between plates that do not meet, and the groups of
plates held together."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .entries import EDGES, GEOM_TOL


@dataclass
class Contact:
    """The straight segment ``start``-``end`` [m] where plates ``plates`` (two names) meet."""

    plates: tuple
    start: np.ndarray
    end: np.ndarray

    @property
    def direction(self) -> np.ndarray:
        d = self.end - self.start
        return d / np.linalg.norm(d)

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.end - self.start))


def segment_gap(a0, a1, b0, b1) -> float:
    """Shortest distance [m] between the 3-D segments a0-a1 and b0-b1 (closest points of the two
    segments, clamped; Ericson, Real-Time Collision Detection, 5.1.9)."""
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    c, b = d1 @ r, d1 @ d2
    den = a * e - b * b
    s = np.clip((b * f - c * e) / den, 0.0, 1.0) if den > 1e-30 * a * e else 0.0
    t = (b * s + f) / e
    if t < 0.0 or t > 1.0:
        t = np.clip(t, 0.0, 1.0)
        s = np.clip((b * t - c) / a, 0.0, 1.0)
    return float(np.linalg.norm(a0 + s * d1 - (b0 + t * d2)))


def _on_segment(p0, p1, q0, q1, tol):
    """The part of segment q0-q1 lying on segment p0-p1 (collinear within ``tol``), or None."""
    d = p1 - p0
    L = np.linalg.norm(d)
    e = d / L
    for q in (q0, q1):
        r = q - p0
        if np.linalg.norm(r - (r @ e) * e) > tol:
            return None
    lo, hi = sorted(((q0 - p0) @ e, (q1 - p0) @ e))
    lo, hi = max(lo, 0.0), min(hi, L)
    return (p0 + lo * e, p0 + hi * e) if hi - lo > tol else None


def contacts(plates, tol: float = GEOM_TOL) -> list:
    """Every :class:`Contact` of two plates: an edge of one lying on an edge of the other, or lying in
    the other's face (a plate standing on another); one contact per pair and segment."""
    out = []
    for i, pa in enumerate(plates):
        for pb in plates[i + 1:]:
            found = []
            for ea in EDGES:
                a0, a1 = pa.edge(ea)
                for eb in EDGES:
                    seg = _on_segment(a0, a1, *pb.edge(eb), tol)
                    if seg is not None:
                        found.append(seg)
                if np.all(pb.distance(np.array([a0, a1])) <= tol):
                    found.append((a0, a1))
            for eb in EDGES:
                b0, b1 = pb.edge(eb)
                if np.all(pa.distance(np.array([b0, b1])) <= tol):
                    found.append((b0, b1))
            pair = (pa.name, pb.name)
            for s0, s1 in found:
                if not any(segment_gap(s0, s1, c.start, c.end) <= tol and abs(np.linalg.norm(s1 - s0) - c.length) <= tol
                           for c in out if c.plates == pair):
                    out.append(Contact(pair, s0, s1))
    return out


def nearest_edges(pa, pb) -> tuple:
    """(gap [m], edge of ``pa``, edge of ``pb``): the two edges of two plates that come closest."""
    return min((segment_gap(*pa.edge(ea), *pb.edge(eb)), ea, eb) for ea in EDGES for eb in EDGES)


def groups(plates, found) -> list:
    """Sets of plate names joined by the contacts ``found`` (directly or through others)."""
    parent = {p.name: p.name for p in plates}

    def root(n):
        while parent[n] != n:
            n = parent[n]
        return n

    for c in found:
        parent[root(c.plates[0])] = root(c.plates[1])
    out: dict = {}
    for p in plates:
        out.setdefault(root(p.name), set()).add(p.name)
    return list(out.values())
