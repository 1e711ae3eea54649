"""Bending curvatures of flat shells at arbitrary points, as a linear map of the DOF vector.

On a shell in the global x-y plane the normal's tilts are beta_x = theta_y and beta_y = -theta_x
(see :mod:`.elements.shell_common`); the curvatures are their derivatives, interpolated with the
element's own shape functions (bilinear on quad4, linear on tri3) at the point:

    kappa_xx = d(beta_x)/dx,  kappa_yy = d(beta_y)/dy,  kappa_xy = d(beta_x)/dy + d(beta_y)/dx

(kappa_xx = -d2w/dx2 on a thin plate). The points are located with :func:`.probe.locate`.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .mesh import NDOF
from .model import SHELL_TYPES, ModelError
from .probe import locate

_XI = np.array([-1.0, 1.0, 1.0, -1.0])
_ETA = np.array([-1.0, -1.0, 1.0, 1.0])
_TX, _TY = 3, 4  # theta_x, theta_y in a node's 6 DOFs


def _shape_gradients(xy: np.ndarray, weights: np.ndarray, is_tri: bool) -> np.ndarray:
    """dN_a/dx, dN_a/dy (2, 4) of one cell with nodes ``xy`` (4, 2) at the point of ``weights``."""
    if is_tri:  # linear triangle: constant gradients; the fourth (repeated) node gets none
        dn = np.array([[-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]])  # d/ds, d/dt of (1-s-t, s, t)
        J = dn @ xy[:3]
        out = np.zeros((2, 4))
        out[:, :3] = np.linalg.solve(J, dn)
        return out
    xi = (weights[1] + weights[2]) - (weights[0] + weights[3])  # the bilinear weights give back (xi, eta)
    eta = (weights[2] + weights[3]) - (weights[0] + weights[1])
    dn = 0.25 * np.array([_XI * (1 + eta * _ETA), _ETA * (1 + xi * _XI)])
    return np.linalg.solve(dn @ xy, dn)


def curvature_matrix(model, points, sets=None, tol: float | None = None) -> sp.csr_matrix:
    """C (3 n_points, n_dof): rows 3i, 3i+1, 3i+2 give kappa_xx, kappa_yy, kappa_xy [1/m] at
    point i of ``points`` (n, 2 or 3) from the DOF vector, on the quad4/tri3 sets (all, or
    ``sets``) of a model whose shells lie in the x-y plane."""
    names = list(model.sets) if sets is None else list(sets)
    cells = [(model.sets[n].etype, model.sets[n].conn) for n in names if model.sets[n].etype in SHELL_TYPES]
    if not cells:
        raise ModelError("the model has no quad4 or tri3 cells to read curvatures on")
    if np.ptp(model.nodes[:, 2]) > 1e-9 * max(np.ptp(model.nodes[:, :2]), 1.0):
        raise ModelError("curvature_matrix reads flat shells in the x-y plane only")
    p = np.asarray(points, dtype=float)
    p = np.column_stack([p[:, :2], np.zeros(len(p))]) if p.shape[1] == 2 else p
    loc = locate(model.nodes, cells, p, tol)
    if not loc.found.all():
        bad = np.flatnonzero(~loc.found)
        raise ModelError(f"{bad.size} point(s) are not on the shells, e.g. {np.round(p[bad[0]], 6).tolist()}")
    is_tri = loc.nodes[:, 3] == loc.nodes[:, 2]
    rows, cols, vals = [], [], []
    for i in range(len(p)):
        g = _shape_gradients(model.nodes[loc.nodes[i], :2], loc.weights[i], bool(is_tri[i]))
        for a, node in enumerate(loc.nodes[i]):
            tx, ty = NDOF * node + _TX, NDOF * node + _TY
            dx, dy = g[0, a], g[1, a]
            rows += [3 * i, 3 * i + 1, 3 * i + 2, 3 * i + 2]
            cols += [ty, tx, ty, tx]
            vals += [dx, -dy, dy, -dx]
    C = sp.csr_matrix((vals, (rows, cols)), shape=(3 * len(p), model.n_dof))
    C.sum_duplicates()
    return C
