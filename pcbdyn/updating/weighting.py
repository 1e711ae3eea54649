"""Row and column weighting of updating equations (thesis sections 4.4 and 4.7).

Column weighting by the parameter values (eq. 4.41) is done when the equations are built
(``p`` argument of :mod:`.equations`); here are the row weights and the TLS weight of b.
"""

from __future__ import annotations

import numpy as np


def unit_row_weights(A) -> np.ndarray:
    """d_i = 1 / ||row i of A|| (thesis eq. 4.42); zero rows get weight 0 (they carry no information)."""
    norms = np.linalg.norm(np.asarray(A), axis=1)
    return np.divide(1.0, norms, out=np.zeros_like(norms), where=norms > 0)


def std_row_weights(sigma) -> np.ndarray:
    """d_i = 1 / sigma_i from the standard deviation of each observation (chi-squares, eqs. 4.26-4.28)."""
    sigma = np.asarray(sigma, float)
    if np.any(sigma <= 0):
        raise ValueError("sigma: every standard deviation must be > 0")
    return 1.0 / sigma


def weight_rows(A, b, d):
    """(D A, D b) with D = diag(d) (thesis eq. 4.23)."""
    d = np.asarray(d, float)
    if d.shape != (np.shape(A)[0],):
        raise ValueError(f"row weights have shape {d.shape}; expected ({np.shape(A)[0]},)")
    return np.asarray(A) * d[:, None], np.asarray(b) * d


def tls_column_weight(A, b, precision_ratio: float = 1.0) -> float:
    """t_{n+1} = (k_A ||A||_F) / (k_b ||b||) for the observation column in TLS (thesis eq. 4.43).

    ``precision_ratio`` = k_A / k_b: the relative error level of A over that of b (1: both
    equally precise; < 1 when A is trusted more).
    """
    nb = np.linalg.norm(b)
    if nb == 0:
        raise ValueError("b is zero: nothing to update (the model already matches the data)")
    return precision_ratio * np.linalg.norm(A) / nb
