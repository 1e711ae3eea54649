"""Orthogonality checks with the model's matrices (thesis eq. 2.7-2.10)."""

from __future__ import annotations

import numpy as np

from pcbdyn.fe.mesh import NDOF


def cross_orthogonality(phi_a, phi_x, M, K=None):
    """Phi_a^T M Phi_x (and Phi_a^T K Phi_x when K is given) (thesis eq. 2.8).

    ``phi_x`` are full-length (expanded) test shapes, or both sets are reduced to the same DOFs
    with the matching reduced M and K. Returns one matrix, or (M_ax, K_ax)."""
    A, X = np.asarray(phi_a), np.asarray(phi_x)
    out_m = np.asarray(A.T @ (M @ X))
    return out_m if K is None else (out_m, np.asarray(A.T @ (K @ X)))


def mixed_orthogonality(phi_x, M, K=None):
    """Phi_x^T M Phi_x (and Phi_x^T K Phi_x) of expanded test shapes (thesis eq. 2.9)."""
    return cross_orthogonality(phi_x, phi_x, M, K)


def off_diagonal_ratio(O) -> np.ndarray:
    """|O_ij| / sqrt(|O_ii O_jj|) with a zero diagonal; the thesis asks for values below 0.1."""
    O = np.asarray(O)
    d = np.sqrt(np.abs(np.diag(O)))
    with np.errstate(invalid="ignore", divide="ignore"):
        R = np.abs(O) / np.outer(d, d)
    np.fill_diagonal(R, 0.0)
    return R


def rigid_translation(n_nodes: int, axis: int = 2) -> np.ndarray:
    """A unit rigid-body translation along ``axis`` (0, 1, 2 for x, y, z) over 6-DOF nodes."""
    r = np.zeros(NDOF * n_nodes)
    r[axis::NDOF] = 1.0
    return r


def static_mass(M, axis: int = 2) -> float:
    """Total mass the model moves in a rigid translation along ``axis``: r^T M r (thesis eq. 2.10), to
    compare with the weighed structure. ``M`` is the full (unconstrained) 6-DOF/node mass matrix."""
    n = M.shape[0]
    if n % NDOF:
        raise ValueError(f"M has {n} rows, not 6 per node: pass the full mass matrix")
    r = rigid_translation(n // NDOF, axis)
    return float(r @ (M @ r))
