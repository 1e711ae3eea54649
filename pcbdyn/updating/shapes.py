"""Mode shapes in the objective: the residual rows of measured shapes against the model's paired modes
read at the measured DOFs, in units of the shape noise, and their Jacobian.

Frequencies of a nearly symmetric structure do not change to first order when one of two symmetric
parameters rises and the other falls (a card in two guides); its shapes do. The rows here give those
shapes a voice beside the frequency rows (thesis eqs. 3.2-3.3), in the chi^2 of eq. 4.28: per paired mode
the measured shape d against the model's u = P phi, scaled by the least-squares modal scale factor
s = u.d / u.u, r = d - s u, each component in units of sigma = (relative shape noise) * rms(d) (a
uniform bound e of eq. 5.73 has the standard deviation e / sqrt 3 of each component's own size, which is
rms(d) e / sqrt 3 on average over the components).

The shape derivatives are the modal sum over the computed modes (eqs. 3.8-3.13) plus the quasi-static
answer of every mode above them, (K + mu M)^-1 less its part along the computed modes (the modal
acceleration correction): one factorisation per evaluation, none per mode and parameter as Nelson's
exact method needs (:func:`.sensitivity.eigenvector_derivative_nelson`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .sensitivity import bilinear_forms, eigen_derivatives


def _solver(K, M, shift: float):
    A = K + shift * M
    if sp.issparse(A):
        lu = spla.splu(sp.csc_matrix(A))
        return lu.solve
    return lambda B: np.linalg.solve(np.asarray(A), B)


def shape_derivatives(K, M, lam, Phi, index, dKs, dMs, shift: float = 0.0, close=()) -> np.ndarray:
    """d phi_i / d p_j (n_params, n_dof, m) of the modes ``index`` of the computed (lam, Phi) (mass
    normalised): the modal sum over Phi (:func:`.sensitivity.eigen_derivatives`, with the normalisation's
    -phi_i^T dM phi_i / 2 along phi_i, eq. 3.13) plus sum over the modes beyond Phi of
    phi_k phi_k^T G / (lambda_i - lambda_k) ~ -phi_k phi_k^T G / (lambda_k + shift), G = (dK - lambda_i dM)
    phi_i. ``shift`` > 0 makes K + shift M regular for a free structure. ``close``: groups (positions in
    ``index``) of modes compared as a plane (:func:`.sensitivity.eigen_derivatives`)."""
    index = np.asarray(index, int)
    lam = np.asarray(lam, float)
    n_par = len(dKs)
    if n_par == 0 or index.size == 0:
        return np.zeros((n_par, Phi.shape[0], index.size))
    phi = Phi[:, index]
    BK, BM = bilinear_forms(Phi, phi, dKs, dMs)
    _, C = eigen_derivatives(BK, BM, lam, index, close)
    for a, i in enumerate(index):
        C[:, i, a] = -0.5 * BM[:, i, a]
    solve = _solver(K, M, shift)
    G = np.stack([np.asarray(dK @ phi) - np.asarray(dM @ phi) * lam[index][None, :] for dK, dM in zip(dKs, dMs)])
    G2 = np.moveaxis(G, 0, 1).reshape(Phi.shape[0], -1)  # (n_dof, n_par * m)
    static = np.asarray(solve(G2)) - Phi @ ((Phi.T @ G2) / (lam + shift)[:, None])
    static = np.moveaxis(static.reshape(Phi.shape[0], n_par, index.size), 1, 0)
    return np.einsum("dk,jkm->jdm", Phi, C) - static


def shape_sigma(d, relative: float) -> float:
    """The standard deviation of each component of measured shape ``d``: ``relative`` (the noise's
    standard deviation as a fraction of a component's size) times rms(d)."""
    return float(relative * np.sqrt(np.mean(np.abs(d) ** 2)))


def shape_residual(d, u, sigma: float) -> np.ndarray:
    """(d - s u) / sigma with the modal scale factor s = u.d / u.u."""
    s = float(u @ d) / float(u @ u)
    return (d - s * u) / sigma


def shape_rows(d, u, du, sigma: float, p):
    """(A, b) of one mode's shape rows in units of ``sigma``: b = (d - s u) / sigma, A = d(s u)/dx (x = dp/p,
    the column weighting of eq. 4.41) / sigma, with s following u (variable projection of the scale).
    ``du`` (n_meas, n_params): d u / d p_j."""
    uu = float(u @ u)
    s = float(u @ d) / uu
    ds = (du.T @ d - 2.0 * s * (du.T @ u)) / uu
    A = (np.outer(u, ds) + s * du) * np.asarray(p, float)[None, :]
    return A / sigma, (d - s * u) / sigma
