"""Expansion of measured shapes to the whole model, and smoothing of measured shapes and FRFs
(thesis ch. 2.2).

* Dynamic (Kidder) expansion of a mode at its own frequency, eq. 2.24 solved three ways:
  "slave" rows (eq. 2.25, via :func:`pcbdyn.fe.reduction.dynamic_expansion`), "master" rows
  (eq. 2.26) and "all" rows (eq. 2.27, least squares). All three are exact when model and mode agree.
* Modal-coordinate expansion, eq. 2.32-2.36, and its smoothing of the measured rows, eq. 2.37.
* SEREP, eq. 2.38-2.43, through :func:`pcbdyn.fe.reduction.serep` (finite-element based) or with
  the measured shapes themselves (eq. 2.43).
* FRF smoothing, thesis 2.2.3: test FRF vectors projected on model FRF vectors computed at
  frequencies shifted by the paired modes' frequency difference.

Shapes are columns; ``measured`` are row numbers in the model's system (K, M or Phi).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from pcbdyn.fe.reduction import dynamic_expansion, serep

#: above this many unknowns the least-squares forms use LSQR instead of a dense solve
DENSE_LIMIT = 3000


def _lstsq(A, B):
    """Least-squares (minimum-norm when underdetermined) solution of A X = B, A sparse or dense."""
    if max(A.shape) <= DENSE_LIMIT:
        Ad = A.toarray() if sp.issparse(A) else np.asarray(A)
        return np.linalg.lstsq(Ad, B, rcond=None)[0]
    A = sp.csr_matrix(A)
    return np.column_stack([spla.lsqr(A, b, atol=1e-14, btol=1e-14, iter_lim=20 * A.shape[1])[0] for b in B.T])


def kidder_expansion(K, M, measured, phi_m, omega, form: str = "slave") -> np.ndarray:
    """Full shapes from measured components by dynamic expansion at each mode's angular frequency.

    ``phi_m`` (n_m,) or (n_m, k), ``omega`` [rad/s] a scalar or one per column. ``form``: "slave"
    uses the slave rows of Z phi = 0 (eq. 2.25), "master" the master rows (eq. 2.26, a
    minimum-norm fit: only as many equations as measured DOFs), "all" both (eq. 2.27, least squares,
    which spreads test and model errors over every equation).
    """
    if form == "slave":
        return dynamic_expansion(K, M, measured, phi_m, omega)
    if form not in ("master", "all"):
        raise ValueError(f"form must be 'slave' (eq. 2.25), 'master' (eq. 2.26) or 'all' (eq. 2.27), got '{form}'")
    n = K.shape[0]
    m = np.atleast_1d(np.asarray(measured, dtype=np.int64))
    s = np.setdiff1d(np.arange(n), m)
    x = np.asarray(phi_m)
    X = x.reshape(m.size, -1)
    w = np.broadcast_to(np.asarray(omega, dtype=float), (X.shape[1],))
    Kc, Mc = sp.csr_matrix(K), sp.csr_matrix(M)
    out = np.zeros((n, X.shape[1]), dtype=np.result_type(X.dtype, float))
    out[m] = X
    for c, wc in enumerate(w):
        Z = (Kc - wc**2 * Mc).tocsr()
        Zm, Zs = Z[m], Z[s]
        if form == "master":
            A, b = Zm[:, s], -(Zm[:, m] @ X[:, c])
        else:
            A = sp.vstack([Zm[:, s], Zs[:, s]])
            b = -np.concatenate([Zm[:, m] @ X[:, c], Zs[:, m] @ X[:, c]])
        out[s, c] = _lstsq(A, b[:, None])[:, 0]
    return out.reshape((n,) + x.shape[1:])


def modal_expansion(Phi_a, phi_xm, measured=None, read=None) -> np.ndarray:
    """Expanded test shapes Phi_a q with modal coordinates q = Phi_am^+ phi_xm (thesis eq. 2.35-2.36).

    The model shapes at the test DOFs are either rows ``measured`` of ``Phi_a`` or ``read @ Phi_a``
    (an interpolation matrix, for points between nodes). The result's unmeasured rows are eq. 2.36
    and its measured rows the smoothed test values of eq. 2.37.
    """
    Phi_a = np.asarray(Phi_a)
    Pm = _at_test(Phi_a, measured, read)
    return Phi_a @ np.linalg.pinv(Pm) @ np.asarray(phi_xm)


def smooth_shapes(Phi_am, phi_xm) -> np.ndarray:
    """Measured shapes projected on the span of the model shapes at the same DOFs (thesis eq. 2.37)."""
    Pm = np.asarray(Phi_am)
    return Pm @ (np.linalg.pinv(Pm) @ np.asarray(phi_xm))


def serep_expansion(Phi_a, measured, phi_xm) -> np.ndarray:
    """Finite-element based SEREP expansion T_SEREP phi_xm with T = Phi_a Phi_am^+ (thesis eq. 2.39, 2.42)."""
    return serep(Phi_a, measured) @ np.asarray(phi_xm)


def serep_test_based(Phi_au, Phi_xm) -> np.ndarray:
    """Unmeasured rows by the finite-element/experimental SEREP version Phi_au Phi_xm^+ Phi_xm
    (thesis eq. 2.41, 2.43): the columns of Phi_au and Phi_xm must be paired modes, scaled alike."""
    Phi_au, Phi_xm = np.asarray(Phi_au), np.asarray(Phi_xm)
    if Phi_au.shape[1] != Phi_xm.shape[1]:
        raise ValueError("Phi_au and Phi_xm need the same number of (paired) modes")
    return Phi_au @ (np.linalg.pinv(Phi_xm) @ Phi_xm)


def _at_test(Phi_a, measured, read):
    if (measured is None) == (read is None):
        raise ValueError("give either measured (row numbers) or read (an interpolation matrix)")
    return Phi_a[np.asarray(measured)] if measured is not None else np.asarray(read @ Phi_a)


def shifted_frequencies(f_update, f_test, f_model) -> np.ndarray:
    """Frequencies at which to compute model FRFs for smoothing (thesis 2.2.3, figure 2.2).

    Each updating frequency is tied to the nearest test resonance f_test[i]; the paired model
    resonance f_model[i] (same order) is moved by the same offset: f_model[i] + (f_u - f_test[i]).
    """
    fu = np.asarray(f_update, dtype=float).ravel()
    fx, fa = np.asarray(f_test, dtype=float).ravel(), np.asarray(f_model, dtype=float).ravel()
    if fx.size != fa.size or fx.size == 0:
        raise ValueError("f_test and f_model must be paired resonances, one each, at least one")
    i = np.argmin(np.abs(fu[:, None] - fx[None, :]), axis=1)
    return fa[i] + (fu - fx[i])


def smooth_frfs(H_x, H_ae, min_fdac: float = 0.0):
    """Smoothed test FRF vectors and the mask of updating frequencies kept (thesis 2.2.3).

    ``H_x`` (n_u, n_resp): test FRF vectors (one reference) at the updating frequencies; ``H_ae``
    (n_u, n_resp): the model's at the shifted frequencies. A line is kept when the FDAC of its two
    vectors exceeds ``min_fdac``; kept test vectors are projected on the span of the kept model
    vectors: h_x* = H_ae H_ae^+ h_x. Returns (H_x smoothed (n_kept, n_resp), keep (n_u,)).
    """
    X, A = np.asarray(H_x), np.asarray(H_ae)
    if X.shape != A.shape:
        raise ValueError(f"H_x and H_ae must have the same shape (n_u, n_resp), got {X.shape} and {A.shape}")
    num = np.abs(np.sum(X.conj() * A, axis=1)) ** 2
    den = np.sum(np.abs(X) ** 2, axis=1) * np.sum(np.abs(A) ** 2, axis=1)
    keep = num > min_fdac * den
    B = A[keep].T
    return (B @ (np.linalg.pinv(B) @ X[keep].T)).T, keep
