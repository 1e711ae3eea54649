"""Eigen-solution of plain (K, M) systems and its parameter sensitivities (thesis section 3.2).

Parameters enter through their matrix derivatives dK/dp_j and dM/dp_j (dense or scipy sparse,
same size as K). Modes are mass-normalised: phi^T M phi = 1, phi^T K phi = lambda = omega^2.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..fe.modal import eigenpairs
from .errors import UpdatingError

def as_dense(A) -> np.ndarray:
    """Dense ndarray view of a dense or scipy-sparse matrix."""
    return A.toarray() if sp.issparse(A) else np.asarray(A)


def pencil_modes(K, M, n_modes: int | None = None):
    """Lowest ``n_modes`` eigenpairs (default: all) of K phi = lambda M phi as (lambda, Phi), sorted,
    Phi mass-normalised; rigid-body modes of a free system are included (lambda ~ 0), so pair
    measured modes with elastic ones only. Solved by the FE engine's :func:`pcbdyn.fe.modal.eigenpairs`.

    Not :func:`pcbdyn.fe.modal.solve_modes`: that one takes a model (its constraints, its rigid-body
    check) and returns elastic :class:`~pcbdyn.fe.modal.Modes` in Hz; this one takes a bare matrix
    pencil, as the sensitivity formulas (thesis section 3.2) do, and returns every eigenpair in lambda.
    """
    if K.shape != M.shape or K.shape[0] != K.shape[1]:
        raise ValueError(f"K {K.shape} and M {M.shape} must be square and of equal size")
    n = K.shape[0]
    k = n if n_modes is None else min(int(n_modes), n)
    lam, Phi, _ = eigenpairs(K, M, n_modes=k, free=True)
    order = np.argsort(lam, kind="stable")[:k]
    return lam[order], Phi[:, order]


def frequencies_hz(lam) -> np.ndarray:
    """Natural frequencies [Hz] from eigenvalues lambda = omega^2 (negatives clipped to 0)."""
    return np.sqrt(np.clip(np.asarray(lam, float), 0.0, None)) / (2 * np.pi)


def _check_derivatives(dKs, dMs):
    if len(dKs) != len(dMs):
        raise ValueError(f"dKs has {len(dKs)} entries but dMs has {len(dMs)}: give one (dK, dM) pair per parameter")


def bilinear_forms(basis, shapes, dKs, dMs):
    """(BK, BM), each (n_params, n_basis, n_shapes): phi_k^T dK_j phi_i and phi_k^T dM_j phi_i for the
    columns k of ``basis`` and i of ``shapes`` (the terms of thesis eqs. 3.6 and 3.11)."""
    _check_derivatives(dKs, dMs)
    BK = np.stack([basis.T @ (dK @ shapes) for dK in dKs]) if dKs else np.zeros((0, basis.shape[1], shapes.shape[1]))
    BM = np.stack([basis.T @ (dM @ shapes) for dM in dMs]) if dMs else np.zeros_like(BK)
    return BK, BM


def eigen_derivatives(BK, BM, lam_basis, index, close=()):
    """Eigenvalue derivatives and the modal-expansion coefficients of the eigenvector derivatives from
    bilinear forms over a basis of modes (:func:`bilinear_forms`; ``lam_basis`` their eigenvalues,
    ``index`` the basis position of each mode i whose derivatives are wanted):

    - d lambda_i / dp_j = phi_i^T (dK_j - lambda_i dM_j) phi_i (thesis eq. 3.6), (n_params, m);
    - C_jki = phi_k^T (dK_j - lambda_i dM_j) phi_i / (lambda_i - lambda_k) for the basis modes k of
      another eigenvalue, 0 for k of the same (eqs. 3.8-3.12), (n_params, n_basis, m): d phi_i / dp_j is
      sum_k C_jki phi_k plus a multiple of phi_i (the mass normalisation's, eq. 3.13, added by the
      caller that needs it).

    ``close``: groups (positions in ``index``) of modes compared with a test as a plane
    (:mod:`pcbdyn.correlation.close_modes`): their turn within it (the coupling over their gap) is met by
    turning the measured shapes, so between them C keeps only the part that keeps mass-orthogonality,
    -phi_k^T dM_j phi_i / 2.

    One formula for updating and for the diagnosis's candidate effects (their forms come from
    element blocks instead of assembled dK, dM)."""
    lam_basis = np.asarray(lam_basis, float)
    index = np.asarray(index, int)
    lam = lam_basis[index]
    B = BK - BM * lam[None, None, :]
    dlam = B[:, index, np.arange(index.size)]
    gap = lam[None, :] - lam_basis[:, None]
    same = np.abs(gap) <= 1e-9 * np.maximum(np.abs(lam)[None, :], 1.0)
    C = np.where(same[None], 0.0, B / np.where(same, 1.0, gap)[None])
    for g in close:
        for a in g:
            partners = index[[b for b in g if b != a]]
            C[:, partners, a] = -0.5 * BM[:, partners, a]
    return dlam, C


def eigenvalue_derivatives(lam, Phi, dKs, dMs) -> np.ndarray:
    """d lambda_i / d p_j = phi_i^T (dK_j - lambda_i dM_j) phi_i (thesis eq. 3.6 in lambda form).

    Returns shape (n_modes, n_params).
    """
    lam = np.asarray(lam, float)
    dlam, _ = eigen_derivatives(*bilinear_forms(Phi, Phi, dKs, dMs), lam, np.arange(lam.size))
    return dlam.T


def frequency_derivatives(lam, Phi, dKs, dMs) -> np.ndarray:
    """d f_i / d p_j [Hz per parameter unit] (thesis eq. 3.6): d lambda / (8 pi^2 f)."""
    f = frequencies_hz(lam)
    if np.any(f <= 0):
        raise UpdatingError("frequency derivatives need elastic modes (f > 0); drop rigid-body modes first")
    return eigenvalue_derivatives(lam, Phi, dKs, dMs) / (8 * np.pi**2 * f[:, None])


def eigenvector_derivative_nelson(K, M, lam_i, phi_i, dK, dM, dlam=None) -> np.ndarray:
    """Exact derivative of one mass-normalised eigenvector of a distinct eigenvalue (Nelson's method).

    Solves (K - lambda M) v = -(dK - lambda dM - dlambda M) phi with the largest component of phi
    held at zero, then adds c phi so that the mass normalisation (thesis eq. 3.13) holds:
    c = -phi^T M v - phi^T dM phi / 2. Uses the full matrices, so no mode truncation error
    (unlike the modal sum of eqs. 3.8-3.14).
    """
    phi = np.asarray(phi_i, float)
    if dlam is None:
        dlam = phi @ (dK @ phi) - lam_i * (phi @ (dM @ phi))
    rhs = -(dK @ phi - lam_i * (dM @ phi) - dlam * (M @ phi))
    k = int(np.argmax(np.abs(phi)))
    Z = sp.lil_matrix(sp.csr_matrix(K) - lam_i * sp.csr_matrix(M))
    Z[k, :] = 0.0
    Z[:, k] = 0.0
    Z[k, k] = 1.0
    rhs[k] = 0.0
    v = spla.spsolve(Z.tocsc(), rhs)
    c = -phi @ (M @ v) - 0.5 * phi @ (dM @ phi)
    return v + c * phi


def eigenvector_derivatives_modal(lam, Phi, i: int, dKs, dMs) -> np.ndarray:
    """d phi_i / d p_j by modal superposition over the available modes (thesis eqs. 3.8-3.14):
    :func:`eigen_derivatives`' coefficients plus beta_ii = -phi_i^T dM phi_i / 2 along phi_i (mass
    normalisation). Truncated to the modes in Phi, so only approximate unless Phi holds all modes;
    needs distinct eigenvalues. Returns shape (n_dof, n_params).
    """
    lam = np.asarray(lam, float)
    gap = lam[i] - lam
    gap[i] = 1.0
    if np.any(np.abs(gap) < 1e-10 * max(abs(lam[i]), 1.0)):
        raise UpdatingError(f"mode {i} has a repeated eigenvalue: eq. 3.12 is invalid for repeated modes")
    BK, BM = bilinear_forms(Phi, Phi[:, i:i + 1], dKs, dMs)
    _, C = eigen_derivatives(BK, BM, lam, [i])
    beta = C[:, :, 0]
    beta[:, i] = -0.5 * BM[:, i, 0]
    return Phi @ beta.T


def perturbation_derivatives(build, p, j: int, rel_step: float = 1e-6):
    """(dK/dp_j, dM/dp_j) by central differences of the matrices (the perturbation method of thesis
    eq. 4.50, made second-order). ``build(p) -> (K, M)`` should assemble only the few elements
    parameter j touches: the difference of the rest cancels anyway, but costs time. Exact for
    parameters that enter linearly (E, density, spring rates); for a shell thickness (membrane ~ t,
    bending ~ t^3) the error is of order rel_step^2."""
    p = np.asarray(p, float)
    h = rel_step * (abs(p[j]) if p[j] != 0 else 1.0)
    up, dn = p.copy(), p.copy()
    up[j] += h
    dn[j] -= h
    (Ku, Mu), (Kd, Md) = build(up), build(dn)
    return (Ku - Kd) / (2 * h), (Mu - Md) / (2 * h)
