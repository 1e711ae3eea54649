"""Location-oriented error indicators: where on the mesh the model disagrees with the test
(thesis section 5.2.1). All work on matrices over measured DOFs (a reduced model, or the
full model with expanded shapes); ``dof_node[i]`` names the node of DOF i, so that DOF values
can be gathered into one value per node and drawn as a map.

- :func:`fbm_residuals`: residual forces of the measured modes, eq. 5.2;
- :func:`emm_error_matrices` / :func:`emm_indicators`: error matrix method, eqs. 5.3-5.13;
- :func:`weighted_emm` / :func:`weighted_emm_indicator`: weighted EMM, eqs. 5.14-5.22.
"""

from __future__ import annotations

import numpy as np

from .sensitivity import as_dense


def _dof_node(dof_node, n):
    if dof_node is None:
        return np.arange(n)
    d = np.asarray(dof_node, int)
    if d.shape != (n,):
        raise ValueError(f"dof_node has shape {d.shape}; expected ({n},): the node of every DOF")
    return d


def node_sum(values, dof_node=None, n_nodes: int | None = None) -> np.ndarray:
    """Sum of |values| over the DOFs of each node; values (n_dof,) or (n_dof, k) -> (n_nodes[, k])."""
    v = np.abs(np.asarray(values))
    d = _dof_node(dof_node, v.shape[0])
    n_nodes = int(d.max()) + 1 if n_nodes is None else int(n_nodes)
    out = np.zeros((n_nodes,) + v.shape[1:])
    np.add.at(out, d, v)
    return out


def _shapes(phi, omega):
    phi = np.asarray(phi)
    phi = phi[:, None] if phi.ndim == 1 else phi
    omega = np.atleast_1d(np.asarray(omega, float))
    if phi.shape[1] != omega.size:
        raise ValueError(f"{phi.shape[1]} shapes but {omega.size} frequencies: give one frequency per mode")
    return phi, omega


def fbm_residuals(K, M, omega_x, phi_x) -> np.ndarray:
    """Residual forces e_i = (K - w_xi^2 M) phi_xi of each measured mode (thesis eq. 5.2), shape
    (n_dof, n_modes); ``omega_x`` in rad/s. They vanish where the model is right: |e_i| at a DOF
    (or summed per node with :func:`node_sum`) is the FBM indicator."""
    phi, om = _shapes(phi_x, omega_x)
    return np.asarray(K @ phi) - np.asarray(M @ phi) * om**2


def fbm_indicator(K, M, omega_x, phi_x, dof_node=None, n_nodes=None) -> np.ndarray:
    """One FBM value per node over all modes: each mode's node residuals scaled to a maximum of
    1 (a mode's residual scale depends on its normalisation and frequency), then summed."""
    e = node_sum(fbm_residuals(K, M, omega_x, phi_x), dof_node, n_nodes)
    peak = e.max(axis=0)
    return (e / np.where(peak > 0, peak, 1.0)).sum(axis=1)


def _mass_normalise(phi, M):
    m = np.einsum("ij,ij->j", phi, np.asarray(M @ phi))
    if np.any(m <= 0):
        raise ValueError("a shape has zero or negative modal mass with the model's M: check the shapes")
    return phi / np.sqrt(m)


def emm_error_matrices(Ka, Ma, omega_a, phi_a, omega_x, phi_x):
    """Stiffness and mass error matrices of the error matrix method (thesis eqs. 5.3-5.9):
    dK ~ Ka (Ka^-1 - Kx^-1) Ka and dM ~ Ma (Ma^-1 - Mx^-1) Ma, the inverses built from the
    available modes, K^-1 ~ Phi Lambda^-1 Phi^T and M^-1 ~ Phi Phi^T (5.7, 5.9).

    Give the paired (correlated) elastic modes only (eqs. 5.10-5.11: an unpaired mode reads as an
    error). Both shape sets are scaled to unit modal mass with Ma (the test mass is unknown)."""
    Ka, Ma = as_dense(Ka), as_dense(Ma)
    pa, wa = _shapes(phi_a, omega_a)
    px, wx = _shapes(phi_x, omega_x)
    if pa.shape != px.shape:
        raise ValueError(f"phi_a {pa.shape} and phi_x {px.shape} must hold the same paired modes")
    pa, px = _mass_normalise(pa, Ma), _mass_normalise(px, Ma)
    flex = (pa / wa**2) @ pa.T - (px / wx**2) @ px.T
    dK = Ka @ flex @ Ka
    dM = Ma @ (pa @ pa.T - px @ px.T) @ Ma
    return dK, dM


def _row_ratio_per_node(E, A, dof_node, n_nodes):
    """sum over the rows l of each node of sum_j |E_lj| / sum_j |A_lj| (Fig. 5.2, eq. 5.13)."""
    den = np.abs(A).sum(axis=1)
    ratio = np.abs(E).sum(axis=1) / np.where(den > 0, den, 1.0)
    return node_sum(ratio, dof_node, n_nodes)


def emm_indicators(Ka, Ma, dK, dM, dof_node=None, n_nodes=None):
    """(e_m, e_k): per node, the row sums of |dM| and |dK| relative to those of |Ma| and |Ka|,
    added over the node's rows (thesis eqs. 5.12-5.13, Fig. 5.2)."""
    Ka, Ma = as_dense(Ka), as_dense(Ma)
    return (_row_ratio_per_node(dM, Ma, dof_node, n_nodes), _row_ratio_per_node(dK, Ka, dof_node, n_nodes))


def weighted_emm(Ka, Ma, omega_x, phi_x) -> np.ndarray:
    """Weighted EMM error matrix E = (Ma A + (Ma A)^T) - (Ka B + (Ka B)^T) with A = Phi_x
    Lambda_x Phi_x^T, B = Phi_x Phi_x^T (thesis eqs. 5.14-5.19).

    With the mass assumed right, E = B dK + dK B (the stiffness error seen through the measured
    modes); with the stiffness assumed right the same matrix, sign reversed, is A dM + dM A
    (eq. 5.20), so |E| serves both readings. Shapes are scaled to unit modal mass with Ma."""
    Ka, Ma = as_dense(Ka), as_dense(Ma)
    px, wx = _shapes(phi_x, omega_x)
    px = _mass_normalise(px, Ma)
    A = (px * wx**2) @ px.T
    B = px @ px.T
    MA, KB = Ma @ A, Ka @ B
    return (MA + MA.T) - (KB + KB.T)


def weighted_emm_indicator(E, dof_node=None, n_nodes=None) -> np.ndarray:
    """e_i = sum of |E_lj| over the rows l of node i and all columns j (thesis eqs. 5.21-5.22)."""
    return node_sum(np.abs(np.asarray(E)).sum(axis=1), dof_node, n_nodes)
