"""Discrete elements: 6-DOF springs (to ground or between two nodes) and point masses with rotary inertia."""

import numpy as np


def spring_matrices(xyz: np.ndarray, prop):
    """Diagonal springs in global axes; 1-node cells tie to ground, 2-node cells tie the nodes together."""
    n_cells, nn, _ = xyz.shape
    k = np.diag(np.asarray(prop.k, dtype=float))
    if nn == 1:
        Ke = np.broadcast_to(k, (n_cells, 6, 6)).copy()
    else:
        Ke = np.broadcast_to(np.block([[k, -k], [-k, k]]), (n_cells, 12, 12)).copy()
    return Ke, np.zeros_like(Ke)


def mass_matrices(xyz: np.ndarray, prop):
    """Point mass on the three translations and rotary inertia on the three rotations."""
    n_cells = xyz.shape[0]
    Me = np.zeros((6, 6))
    Me[:3, :3] = prop.m * np.eye(3)
    Me[3:, 3:] = prop.inertia_matrix()
    Me = np.broadcast_to(Me, (n_cells, 6, 6)).copy()
    return np.zeros_like(Me), Me
