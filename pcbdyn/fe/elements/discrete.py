"""Discrete elements: 6-DOF springs (to ground or between two nodes) and point masses with rotary inertia."""

import numpy as np

from ..model import ModelError


def spring_stiffness(k) -> np.ndarray:
    """The 6x6 spring matrix from six diagonal values or a full symmetric 6x6 (coupled terms)."""
    k = np.asarray(k, dtype=float)
    if k.shape == (6,):
        return np.diag(k)
    if k.shape != (6, 6) or not np.allclose(k, k.T, rtol=1e-12, atol=0.0):
        raise ModelError("SpringProperty.k must be six values (diagonal) or a symmetric 6x6 matrix, global axes")
    return k


def point_spring(weights, k) -> np.ndarray:
    """The stiffness on a cell's nodes of a spring ``k`` (6x6) to ground at the point whose motion
    ``weights`` (one per node) interpolate: (w w^T) (x) k (one node, weight 1: k itself)."""
    w = np.asarray(weights, float)
    return np.kron(np.outer(w, w), k)


def spring_matrices(xyz: np.ndarray, prop):
    """Springs in global axes; 1-node cells tie to ground, 2-node cells tie the nodes together; with
    ``prop.weights`` a cell ties to ground the point its nodes interpolate: (w w^T) (x) k."""
    n_cells, nn, _ = xyz.shape
    k = spring_stiffness(prop.k)
    if prop.weights is not None:
        Ke = np.broadcast_to(point_spring(prop.weights, k), (n_cells, 6 * nn, 6 * nn)).copy()
    elif nn == 1:
        Ke = np.broadcast_to(k, (n_cells, 6, 6)).copy()
    else:
        Ke = np.broadcast_to(np.block([[k, -k], [-k, k]]), (n_cells, 12, 12)).copy()
    return Ke, np.zeros_like(Ke)


def rigid_fit(xyz: np.ndarray, prop):
    """Where the body of a footprint mass sits and how it moves: the first sample point of each
    cell (n_cells, 3) and G (n_cells, 6, 3 nn), the least-squares rigid motion (u_b, theta_b) of
    the sample points' translations per unit translation of the cell's nodes (see
    :func:`mass_matrices`)."""
    n_cells, nn, _ = xyz.shape
    W = np.eye(nn) if prop.footprint is None else np.asarray(prop.footprint, float)
    if W.ndim != 2 or W.shape[1] != nn:
        raise ModelError(f"MassProperty.footprint must be (n_samples, {nn}) weights of the cell's nodes, got {W.shape}")
    ns = W.shape[0]
    samples = np.einsum("sn,cnk->csk", W, xyz)
    r = samples - samples[:, :1, :]
    A = np.zeros((n_cells, ns, 3, 6))
    A[:, :, :, :3] = np.eye(3)
    A[:, :, 0, 4], A[:, :, 0, 5] = r[..., 2], -r[..., 1]  # u = u_b + theta_y z - theta_z y
    A[:, :, 1, 3], A[:, :, 1, 5] = -r[..., 2], r[..., 0]  # v = v_b - theta_x z + theta_z x
    A[:, :, 2, 3], A[:, :, 2, 4] = r[..., 1], -r[..., 0]  # w = w_b + theta_x y - theta_y x
    return samples[:, 0, :], np.linalg.pinv(A.reshape(n_cells, 3 * ns, 6)) @ np.kron(W, np.eye(3))


def mass_matrices(xyz: np.ndarray, prop):
    """A rigid body of mass m and rotary inertia J at a cell's first node, or at the first sample
    point of ``prop.footprint``. A one-node cell carries it on that node's six DOFs. A cell of
    three or more nodes (a footprint) moves the body with the least-squares rigid motion of the
    translations of points sampling the footprint (the nodes themselves, or ``prop.footprint``'s
    interpolation weights), as an RBE3 link that adds no stiffness: u_s = u_b + theta_b x r_s, so M = G^T diag(m, m, m, J) G with G the pseudo-inverse of
    that map; a rotary inertia then acts on the slope of the footprint, which converges with the
    mesh, not on one node's rotations, which a refined shell mesh decouples."""
    n_cells, nn, _ = xyz.shape
    J = prop.inertia_matrix()
    if not prop.m >= 0 or J.shape != (3, 3) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) < 0):
        raise ModelError("MassProperty needs m >= 0 and inertia as 3 values >= 0 or a positive semi-definite 3x3")
    Mb = np.zeros((6, 6))
    Mb[:3, :3] = prop.m * np.eye(3)
    Mb[3:, 3:] = J
    if nn == 1:
        Me = np.broadcast_to(Mb, (n_cells, 6, 6)).copy()
        return np.zeros_like(Me), Me
    _, G = rigid_fit(xyz, prop)
    Mt = np.einsum("cai,ab,cbj->cij", G, Mb, G)
    Me = np.zeros((n_cells, nn, 6, nn, 6))
    Me[:, :, :3, :, :3] = Mt.reshape(n_cells, nn, 3, nn, 3)
    Me = Me.reshape(n_cells, 6 * nn, 6 * nn)
    return np.zeros_like(Me), Me
