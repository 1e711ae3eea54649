"""Model reduction and expansion between master DOFs and the whole model (thesis ch. 2.2).

All functions work on one matrix system (K, M) of size n, usually the constrained matrices of a
model (:func:`pcbdyn.fe.modal.reduced_system`); ``masters`` are row numbers in that system
(:func:`master_index` converts global DOF numbers). Every transformation T has shape (n, n_m) with
T[masters] = I, so that x = T x_m, and reduced matrices are T^T K T, T^T M T.

* Guyan (static) condensation, eq. 2.14-2.16: x_s = -K_ss^-1 K_sm x_m.
* Dynamic (Kidder) reduction at a frequency, eq. 2.19-2.23: x_s = -Z_ss^-1 Z_sm x_m with
  Z = K - omega^2 M; exact for a mode at its own frequency, hence the expansion primitive
  (eq. 2.25) for measured shapes.
* SEREP, eq. 2.38-2.43: T = Phi Phi_m^+, exact for the modes in Phi.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .linsolve import SingularMatrixError, factorize
from .model import ModelError


def master_index(reduction, dofs) -> np.ndarray:
    """Positions in the constrained system of global DOF numbers ``dofs`` (which must be independent:
    not fixed, not an MPC slave, touched by an element)."""
    dofs = np.atleast_1d(np.asarray(dofs, dtype=np.int64)).ravel()
    pos = np.searchsorted(reduction.independent, dofs)
    pos = np.minimum(pos, reduction.independent.size - 1)
    bad = reduction.independent[pos] != dofs
    if bad.any():
        raise ModelError(
            f"master DOFs {dofs[bad].tolist()} are not independent unknowns of the model (fixed, "
            "MPC slaves or not connected to any element): choose other masters"
        )
    return pos


def _partition(n: int, masters) -> tuple[np.ndarray, np.ndarray]:
    m = np.atleast_1d(np.asarray(masters, dtype=np.int64)).ravel()
    if m.size == 0 or m.min() < 0 or m.max() >= n or np.unique(m).size != m.size:
        raise ValueError(f"masters must be distinct row numbers in 0..{n - 1}")
    s = np.setdiff1d(np.arange(n), m)
    return m, s


def _blocks(A, m, s):
    A = sp.csr_matrix(A)
    As = A[s]
    return A[m][:, m], A[m][:, s], As[:, m], As[:, s]


def _transformation(n, m, s, Ts) -> np.ndarray:
    T = np.zeros((n, m.size), dtype=Ts.dtype)
    T[m, np.arange(m.size)] = 1.0
    T[s] = Ts
    return T


def _slave_map(Z, m, s, spd) -> np.ndarray:
    """-Z_ss^-1 Z_sm (n_s, n_m), dense."""
    _, _, Zsm, Zss = _blocks(Z, m, s)
    if s.size == 0:
        return np.zeros((0, m.size))
    try:
        return -factorize(Zss, spd=spd).solve(Zsm.toarray())
    except SingularMatrixError as exc:
        raise ModelError(
            "the slave partition is singular (slave DOFs with no stiffness of their own, or omega is a "
            "natural frequency of the model with the masters held): add those DOFs to the masters"
        ) from exc


def project(T, K, M):
    """T^T K T and T^T M T (dense, n_m x n_m)."""
    return np.asarray(T.T @ (K @ T)), np.asarray(T.T @ (M @ T))


def guyan(K, M, masters):
    """Guyan static condensation onto ``masters`` (thesis eq. 2.14-2.16): (T, K_G, M_G)."""
    n = K.shape[0]
    m, s = _partition(n, masters)
    T = _transformation(n, m, s, _slave_map(K, m, s, spd=True))
    KG, MG = project(T, K, M)
    return T, KG, MG


def dynamic_reduction(K, M, masters, omega: float):
    """Dynamic (Kidder) reduction at angular frequency ``omega`` [rad/s] (thesis eq. 2.19-2.23):
    (T, Z_dyn) with Z_dyn = Z_mm - Z_ms Z_ss^-1 Z_sm = T^T Z T, Z = K - omega^2 M."""
    n = K.shape[0]
    m, s = _partition(n, masters)
    Z = sp.csr_matrix(K) - omega**2 * sp.csr_matrix(M)
    T = _transformation(n, m, s, _slave_map(Z, m, s, spd=False))
    return T, np.asarray(T.T @ (Z @ T))


def dynamic_expansion(K, M, masters, x_master, omega):
    """Full vectors from master values: x_s = -(K_ss - w^2 M_ss)^-1 (K_sm - w^2 M_sm) x_m (thesis eq.
    2.25). ``x_master`` (n_m,) or (n_m, k); ``omega`` [rad/s] a scalar or one per column (each
    measured mode at its own frequency). Returns (n,) or (n, k)."""
    n = K.shape[0]
    m, s = _partition(n, masters)
    x = np.asarray(x_master)
    X = x.reshape(m.size, -1)
    w = np.broadcast_to(np.asarray(omega, dtype=float), (X.shape[1],))
    out = np.zeros((n, X.shape[1]), dtype=np.result_type(X.dtype, float))
    out[m] = X
    if s.size:
        Kr, Mr = sp.csr_matrix(K), sp.csr_matrix(M)
        _, _, Ksm, Kss = _blocks(Kr, m, s)
        _, _, Msm, Mss = _blocks(Mr, m, s)
        for c, wc in enumerate(w):
            Zss = (Kss - wc**2 * Mss).tocsc()
            try:
                out[s, c] = -factorize(Zss, spd=False).solve((Ksm - wc**2 * Msm) @ X[:, c])
            except SingularMatrixError as exc:
                raise ModelError(
                    f"K_ss - w^2 M_ss is singular at {wc / (2 * np.pi):.6g} Hz (a natural frequency of the "
                    "model with the masters held): add masters near where that mode moves"
                ) from exc
    return out.reshape((n,) + x.shape[1:])


def serep(shapes, masters) -> np.ndarray:
    """SEREP transformation T = Phi Phi_m^+ (thesis eq. 2.39), shapes (n, n_modes): x = T x_m
    expands master values (eq. 2.42), and T^T K T, T^T M T keep the modes' frequencies exactly
    when there are at least as many masters as modes and Phi_m has full column rank."""
    Phi = np.asarray(shapes)
    m = np.atleast_1d(np.asarray(masters, dtype=np.int64)).ravel()
    if m.size == 0 or m.min() < 0 or m.max() >= Phi.shape[0]:
        raise ValueError(f"masters must be row numbers in 0..{Phi.shape[0] - 1}")
    Pm = Phi[m]
    if np.linalg.matrix_rank(Pm) < Phi.shape[1]:
        raise ModelError(
            f"the {Phi.shape[1]} modes are not independent at the {m.size} masters: add masters "
            "(at least one per mode, where the modes differ)"
        )
    return Phi @ np.linalg.pinv(Pm)
