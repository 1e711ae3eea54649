"""FRF correlation: FRAC per FRF (thesis eq. 2.5) and FDAC between frequency lines (eq. 2.6)."""

from __future__ import annotations

import numpy as np


def frac(H_x, H_a) -> np.ndarray:
    """FRAC of each FRF over the frequency lines: |sum_l h_a^* h_x|^2 / (sum |h_a|^2 sum |h_x|^2) (eq. 2.5).

    ``H_x``, ``H_a``: complex arrays with frequency first, (n_freq, ...) on the same lines; the
    result has the remaining shape (e.g. (n_resp, n_ref)). A global frequency shift or a damping
    difference lowers FRAC even when the curves look alike.
    """
    X, A = np.asarray(H_x), np.asarray(H_a)
    if X.shape != A.shape:
        raise ValueError(f"FRF arrays must have the same shape, got {X.shape} and {A.shape}")
    num = np.abs(np.sum(A.conj() * X, axis=0)) ** 2
    den = np.sum(np.abs(A) ** 2, axis=0) * np.sum(np.abs(X) ** 2, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)


def fdac(H_x, H_a) -> np.ndarray:
    """FDAC matrices (n_ref, n_freq_x, n_freq_a) (thesis eq. 2.6): for each reference column j, the
    squared cosine between the response vector h_xj(w_x) measured at one frequency and the model's
    h_aj(w_a) at another. A model that is right up to a frequency shift has its ridge of ones off
    the diagonal, at w_a = w_x times the shift.

    ``H_x`` (n_fx, n_resp, n_ref), ``H_a`` (n_fa, n_resp, n_ref); 2-D inputs mean one reference.
    """
    X, A = np.asarray(H_x), np.asarray(H_a)
    if X.ndim == 2:
        X = X[:, :, None]
    if A.ndim == 2:
        A = A[:, :, None]
    if X.shape[1:] != A.shape[1:]:
        raise ValueError(f"FRFs need the same response and reference DOFs, got {X.shape[1:]} and {A.shape[1:]}")
    num = np.abs(np.einsum("xrj,arj->jxa", X.conj(), A)) ** 2
    nx = np.sum(np.abs(X) ** 2, axis=1).T  # (n_ref, n_fx)
    na = np.sum(np.abs(A) ** 2, axis=1).T
    den = nx[:, :, None] * na[:, None, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
