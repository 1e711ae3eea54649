"""Discrete elements: 6-DOF springs (to ground or between two nodes) and point masses with rotary inertia."""

import numpy as np

from ..model import ModelError


def _spring_stiffness(k) -> np.ndarray:
    """The 6x6 spring matrix from six diagonal values or a full symmetric 6x6 (coupled terms)."""
    k = np.asarray(k, dtype=float)
    if k.shape == (6,):
        return np.diag(k)
    if k.shape != (6, 6) or not np.allclose(k, k.T, rtol=1e-12, atol=0.0):
        raise ModelError("SpringProperty.k must be six values (diagonal) or a symmetric 6x6 matrix, global axes")
    return k


def spring_matrices(xyz: np.ndarray, prop):
    """Springs in global axes; 1-node cells tie to ground, 2-node cells tie the nodes together."""
    n_cells, nn, _ = xyz.shape
    k = _spring_stiffness(prop.k)
    if nn == 1:
        Ke = np.broadcast_to(k, (n_cells, 6, 6)).copy()
    else:
        Ke = np.broadcast_to(np.block([[k, -k], [-k, k]]), (n_cells, 12, 12)).copy()
    return Ke, np.zeros_like(Ke)


def mass_matrices(xyz: np.ndarray, prop):
    """Point mass on the three translations and rotary inertia on the three rotations."""
    n_cells = xyz.shape[0]
    J = prop.inertia_matrix()
    if not prop.m >= 0 or J.shape != (3, 3) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) < 0):
        raise ModelError("MassProperty needs m >= 0 and inertia as 3 values >= 0 or a positive semi-definite 3x3")
    Me = np.zeros((6, 6))
    Me[:3, :3] = prop.m * np.eye(3)
    Me[3:, 3:] = J
    Me = np.broadcast_to(Me, (n_cells, 6, 6)).copy()
    return np.zeros_like(Me), Me
