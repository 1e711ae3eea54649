"""Springs distributed along a line of element edges (2-node cells), per unit length: a card guide
or wedge-lock holding a board edge (thesis section 7.4.1 and Fig. 7.34: translations held, a rotational
stiffness per unit length about the edge).

The six springs per unit length act in the edge frame: axis 1 along the edge, axis 3 along
``prop.normal`` (made orthogonal to the edge), axis 2 = 3 x 1. All six displacement components are
interpolated linearly between the two nodes and the stiffness is integrated consistently
(2-point Gauss, exact for linear fields): K = integral of N^T k N ds, i.e. L/6 [[2, 1], [1, 2]]
per spring. A uniform motion thus gives each node k L / 2, as a lumped (tributary length) rule
would, but a linearly varying one gives the exact nodal forces of the distributed spring. No mass.
"""

from __future__ import annotations

import numpy as np

from ..model import ModelError
from .line_frame import line_axes

_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(2)
_XI = 0.5 * (_GAUSS_X + 1.0)
_WXI = 0.5 * _GAUSS_W


def edge_frame(xyz: np.ndarray, normal) -> tuple[np.ndarray, np.ndarray]:
    """Lengths (n,) and rotations (n, 3, 3) whose rows are the edge axes 1, 2, 3 in global coordinates."""
    if np.shape(normal) != (3,):
        raise ModelError("EdgeSpringProperty.normal must be a 3-vector in global axes")
    L, e1, e3 = line_axes(
        xyz, normal, "edge spring", "EdgeSpringProperty.normal must be the normal of the shell whose edge is held"
    )
    return L, np.stack([e1, np.cross(e3, e1), e3], axis=1)


def matrices(xyz: np.ndarray, prop):
    """Edge-spring K (n_cells, 12, 12) in global axes for 2-node cells ``xyz`` (n_cells, 2, 3); M is zero."""
    k = np.asarray(prop.k, dtype=float)
    if k.shape != (6,) or np.any(k < 0):
        raise ModelError(f"EdgeSpringProperty.k must be six values >= 0 (per unit length), got {prop.k}")
    xyz = np.asarray(xyz, dtype=float)
    L, R = edge_frame(xyz, prop.normal)
    kt = np.einsum("nia,i,nib->nab", R, k[:3], R)  # translational springs per length, global
    kr = np.einsum("nia,i,nib->nab", R, k[3:], R)  # rotational springs per length, global
    k6 = np.zeros((L.size, 6, 6))
    k6[:, :3, :3] = kt
    k6[:, 3:, 3:] = kr
    N = np.stack([1.0 - _XI, _XI], axis=1)  # (gauss, node)
    nn = np.einsum("g,ga,gb->ab", _WXI, N, N)  # integral of N^T N over [0, 1]
    K = np.einsum("n,ab,nij->naibj", L, nn, k6).reshape(L.size, 12, 12)
    return K, np.zeros_like(K)
