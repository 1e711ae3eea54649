"""Reading a shell model at arbitrary points through the element shape functions.

Each point is located on the shell surface (quad4 and tri3 cells, flat or curved in 3-D): the
cells whose centroids are nearest (a KD-tree) are candidates, the point is projected on each
candidate (inverse bilinear map by projected Gauss-Newton for quad4, barycentric coordinates for
tri3, both clamped to the cell), and the nearest projection wins. The interpolation matrix P then
gives the model's displacement at the points along given directions: u_points = P @ u, with the
bilinear (quad4) or linear (tri3) shape functions applied to the translational DOFs.

Points farther than ``tol`` from every cell are off the model: they raise :class:`ProbeError`
(listing them) or, with ``missing="mask"``, get an all-zero row and ``found = False``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .mesh import NDOF
from .model import SHELL_TYPES, ModelError

_XI = np.array([-1.0, 1.0, 1.0, -1.0])
_ETA = np.array([-1.0, -1.0, 1.0, 1.0])
_ITER = 30
#: a point's projection has converged once its (xi, eta) moves no more than this in a step
_CONVERGED = 1e-13


class ProbeError(ModelError):
    """Points that do not lie on the shell surface within the tolerance."""


@dataclass
class Location:
    """Where each point lies: cell number (in the order of the cells given), its node numbers (n, 4;
    a triangle repeats its last node with weight 0), shape-function weights (n, 4), distance from
    the surface [m] and whether it is within the tolerance."""

    cell: np.ndarray
    nodes: np.ndarray
    weights: np.ndarray
    distance: np.ndarray
    found: np.ndarray


@dataclass
class Probe:
    """Interpolation matrix P (n_rows, n_dof) and where each row's point lies."""

    P: sp.csr_matrix
    location: Location

    @property
    def found(self) -> np.ndarray:
        return self.location.found


def _quad_weights(xi, eta):
    return 0.25 * (1 + xi[:, None] * _XI) * (1 + eta[:, None] * _ETA)


def _project_quads(X, p):
    """Closest point on bilinear patches X (m, 4, 3) to points p (m, 3): (weights (m, 4), distance).
    A point stops iterating once its (xi, eta) moves less than :data:`_CONVERGED` in a step (two to
    four steps inside a cell); points beside a distorted cell, clamped to its edge, may swing between
    its sides to the last of :data:`_ITER` steps."""
    xi = np.zeros(len(p))
    eta = np.zeros(len(p))
    on = np.arange(len(p))
    for _ in range(_ITER):
        Xo, x0, e0 = X[on], xi[on], eta[on]
        dxi = 0.25 * _XI * (1 + e0[:, None] * _ETA)
        deta = 0.25 * _ETA * (1 + x0[:, None] * _XI)
        r = p[on] - np.einsum("ma,mak->mk", _quad_weights(x0, e0), Xo)
        a = np.einsum("ma,mak->mk", dxi, Xo)
        b = np.einsum("ma,mak->mk", deta, Xo)
        aa, ab, bb = (a * a).sum(1), (a * b).sum(1), (b * b).sum(1)
        ra, rb = (r * a).sum(1), (r * b).sum(1)
        det = aa * bb - ab * ab
        det = np.where(np.abs(det) > 0, det, 1.0)
        xi[on] = np.clip(x0 + (bb * ra - ab * rb) / det, -1.0, 1.0)
        eta[on] = np.clip(e0 + (aa * rb - ab * ra) / det, -1.0, 1.0)
        on = on[np.maximum(np.abs(xi[on] - x0), np.abs(eta[on] - e0)) > _CONVERGED]
        if not on.size:
            break
    w = _quad_weights(xi, eta)
    return w, np.linalg.norm(p - np.einsum("ma,mak->mk", w, X), axis=1)


def segment_parameter(p, a, b):
    """Parameter t in [0, 1] of the closest point on segments a-b to p (all (m, dim))."""
    d = b - a
    dd = (d * d).sum(1)
    return np.clip(((p - a) * d).sum(1) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)


def _project_tris(X, p):
    """Closest point on triangles X (m, 3, 3) to points p: (barycentric weights (m, 3), distance)."""
    a, b, c = X[:, 0], X[:, 1], X[:, 2]
    e1, e2, r = b - a, c - a, p - a
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    r1, r2 = (r * e1).sum(1), (r * e2).sum(1)
    det = d11 * d22 - d12 * d12
    det = np.where(np.abs(det) > 0, det, 1.0)
    s = (d22 * r1 - d12 * r2) / det
    t = (d11 * r2 - d12 * r1) / det
    w = np.column_stack([1 - s - t, s, t])
    inside = np.all(w >= 0, axis=1)
    if not inside.all():
        o = ~inside
        cand = []
        for i, j in ((0, 1), (1, 2), (2, 0)):
            u = segment_parameter(p[o], X[o, i], X[o, j])
            wi = np.zeros((o.sum(), 3))
            wi[:, i] = 1 - u
            wi[:, j] = u
            cand.append(wi)
        cand = np.stack(cand)  # (3, mo, 3)
        dist = np.linalg.norm(p[o][None] - np.einsum("emv,mvk->emk", cand, X[o]), axis=2)
        w[o] = cand[np.argmin(dist, axis=0), np.arange(o.sum())]
    return w, np.linalg.norm(p - np.einsum("mv,mvk->mk", w, X), axis=1)


def _gather_cells(cells):
    """Cells as (n_cells, 4) node numbers with a triangle flag (a triangle repeats its last node)."""
    conns, tri = [], []
    for etype, conn in cells:
        conn = np.atleast_2d(np.asarray(conn, dtype=np.int64))
        if etype == "quad4":
            conns.append(conn)
            tri.append(np.zeros(len(conn), dtype=bool))
        elif etype == "tri3":
            conns.append(np.column_stack([conn, conn[:, 2]]))
            tri.append(np.ones(len(conn), dtype=bool))
        else:
            raise ModelError(f"probe reads shell cells only (quad4, tri3), got '{etype}'")
    if not conns:
        raise ModelError("the model has no quad4 or tri3 cells to read the points on")
    return np.vstack(conns), np.concatenate(tri)


def _project(nodes, conn, is_tri, cand, p):
    """Weights (m, 4) and distance (m,) of points p projected on cells ``cand``."""
    m = len(cand)
    w = np.zeros((m, 4))
    dist = np.zeros(m)
    t = is_tri[cand]
    if (~t).any():
        w[~t], dist[~t] = _project_quads(nodes[conn[cand[~t]]], p[~t])
    if t.any():
        w3, dist[t] = _project_tris(nodes[conn[cand[t], :3]], p[t])
        w[t, :3] = w3
    return w, dist


class Locator:
    """Points located on the shell cells ``cells`` (iterable of (etype, conn)) of ``nodes``: the cells'
    search tree built once for the many point sets a candidate generator locates on one mesh.

    ``tol`` [m]: the largest distance from the surface accepted (default: a tenth of the median
    cell edge)."""

    def __init__(self, nodes, cells, tol: float | None = None):
        self.nodes = np.asarray(nodes, dtype=float)
        self.conn, self.is_tri = _gather_cells(cells)
        X = self.nodes[self.conn]
        cent = np.where(self.is_tri[:, None], X[:, :3].mean(1), X.mean(1))
        edges = np.linalg.norm(X - np.roll(X, 1, axis=1), axis=2)
        self.tol = 0.1 * float(np.median(edges.max(1))) if tol is None else tol
        self.reach = float(np.linalg.norm(X - cent[:, None], axis=2).max(1).max())
        self.tree = cKDTree(cent)

    def __call__(self, points, k: int = 8) -> Location:
        """Where ``points`` (n, 3) lie: the ``k`` nearest cells (by centroid) are tried first; points
        not within the tolerance of any of them are tried against every cell whose centroid is close
        enough to possibly contain them."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        nodes, conn, is_tri, tol = self.nodes, self.conn, self.is_tri, self.tol
        kk = min(k, len(conn))
        _, cand = self.tree.query(p, k=kk)
        cand = cand.reshape(len(p), kk)
        w, d = _project(nodes, conn, is_tri, cand.ravel(), np.repeat(p, kk, axis=0))
        w, d = w.reshape(len(p), kk, 4), d.reshape(len(p), kk)
        best = np.argmin(d, axis=1)
        rows = np.arange(len(p))
        cell, weight, dist = cand[rows, best], w[rows, best], d[rows, best]
        far = np.flatnonzero(dist > tol)  # big cells next to small ones, or points off the mesh
        if far.size:  # every cell close enough to hold them, projected at once
            near = self.tree.query_ball_point(p[far], self.reach + tol)
            owner = np.repeat(far, [len(c) for c in near])
            more = np.fromiter((j for c in near for j in c), dtype=np.int64, count=owner.size)
            wi, di = _project(nodes, conn, is_tri, more, p[owner])
            order = np.lexsort((di, owner))  # per point, its nearest cell first
            first = order[np.r_[True, owner[order][1:] != owner[order][:-1]]] if owner.size else order
            better = di[first] < dist[owner[first]]
            i, j = owner[first][better], first[better]
            cell[i], weight[i], dist[i] = more[j], wi[j], di[j]
        return Location(cell, conn[cell], weight, dist, dist <= tol)


def locate(nodes, cells, points, tol: float | None = None, k: int = 8) -> Location:
    """Locate ``points`` (n, 3) on the shell cells ``cells`` (iterable of (etype, conn)) once
    (:class:`Locator`)."""
    return Locator(nodes, cells, tol)(points, k)


def _directions(directions, n):
    d = np.asarray(directions, dtype=float)
    d = np.tile(d, (n, 1)) if d.shape == (3,) else d.reshape(n, 3)
    norm = np.linalg.norm(d, axis=1)
    if np.any(norm == 0):
        raise ModelError("a probe direction is the zero vector")
    return d / norm[:, None]


def interpolation_matrix(nodes, cells, points, directions=(0.0, 0.0, 1.0), tol: float | None = None,
                         missing: str = "raise", n_dof: int | None = None) -> Probe:
    """P (n_points, n_dof) with (P @ u)[i] = u(point_i) . direction_i, u the 6-DOF/node vector.

    One row per point; give a point twice to read it in two directions. ``missing``: "raise"
    (default) lists the points off the model in a :class:`ProbeError`; "mask" leaves their rows zero
    and reports them in ``Probe.found``.
    """
    if missing not in ("raise", "mask"):
        raise ValueError(f"missing must be 'raise' or 'mask', got '{missing}'")
    nodes = np.asarray(nodes, dtype=float)
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    loc = locate(nodes, cells, p, tol)
    if missing == "raise" and not loc.found.all():
        bad = np.flatnonzero(~loc.found)
        listed = "; ".join(f"#{i} at {np.round(p[i], 6).tolist()} is {loc.distance[i]:.3g} m away" for i in bad[:10])
        raise ProbeError(
            f"{bad.size} point(s) are not on the model: {listed}{' ...' if bad.size > 10 else ''}. "
            "Check that the points are in the model's frame and units, or widen tol"
        )
    d = _directions(directions, len(p))
    n_dof = NDOF * len(nodes) if n_dof is None else n_dof
    w = loc.weights * loc.found[:, None]
    rows = np.repeat(np.arange(len(p)), 12)
    cols = (NDOF * loc.nodes[:, :, None] + np.arange(3)).reshape(len(p), 12).ravel()
    vals = (w[:, :, None] * d[:, None, :]).reshape(len(p), 12).ravel()
    P = sp.csr_matrix((vals, (rows, cols)), shape=(len(p), n_dof))
    P.eliminate_zeros()
    return Probe(P, loc)


def model_probe(model, points, directions=(0.0, 0.0, 1.0), sets=None, tol: float | None = None,
                missing: str = "raise") -> Probe:
    """:func:`interpolation_matrix` on the quad4/tri3 element sets of ``model`` (all, or ``sets``)."""
    names = list(model.sets) if sets is None else list(sets)
    cells = [(model.sets[n].etype, model.sets[n].conn) for n in names if model.sets[n].etype in SHELL_TYPES]
    return interpolation_matrix(model.nodes, cells, points, directions, tol, missing, model.n_dof)
