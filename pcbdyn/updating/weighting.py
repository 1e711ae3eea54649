"""Row and column weighting of updating equations (thesis sections 4.4 and 4.7).

Column weighting by the parameter values (eq. 4.41) is done when the equations are built
(``p`` argument of :mod:`.equations`); here are the row weights and the TLS weight of b.
"""

from __future__ import annotations

import numpy as np

from .errors import UpdatingError


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
        raise UpdatingError("b is zero: nothing to update (the model already matches the data)")
    return precision_ratio * np.linalg.norm(A) / nb


#: redraws of the stated noise on measured data that measure its effect on A and b
NOISE_REDRAWS = 3


def tls_column_weight_from_noise(A, b, redraws) -> float | None:
    """t_{n+1} of eq. 4.43 with the precision coefficients taken from the measurement noise
    itself: ``redraws`` are equations (A_d, b_d) built again from the measured data with the
    stated noise drawn once more (eqs. 5.72-5.74, a parametric bootstrap), so k_A ||A||_F and
    k_b ||b|| are the observed error norms. TLS assumes errors of one size in every entry of
    [A, t b]; the error of A is spread over its n columns, so b's column is scaled to carry the
    error of one column of A: t = ||dA||_F / (sqrt(n) ||db||) (rms over the redraws). None when
    A or b does not change (no noise, or equations whose A holds no measured data, where LS, not
    TLS, is the model)."""
    A, b = np.asarray(A), np.asarray(b)
    dA = np.sqrt(np.mean([np.linalg.norm(np.asarray(Ad) - A) ** 2 for Ad, _ in redraws]))
    db = np.sqrt(np.mean([np.linalg.norm(np.asarray(bd) - b) ** 2 for _, bd in redraws]))
    if not (dA > 0 and db > 0):
        return None
    return float(dA / (np.sqrt(A.shape[1]) * db))
