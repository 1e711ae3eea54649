"""The reported uncertainty of an effect (:mod:`pcbdyn.diagnosis.uncertainty`): on a linear residual
whose rows fall in folds, the jackknife over the folds measures the noise as the fit's covariance
does when the folds agree, and far more when one fold carries an error the others do not."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from pcbdyn.diagnosis.uncertainty import MODEL_FORM, jackknife_cov, parts

N_FOLDS, ROWS = 8, 40


class _Linear:
    """A residual r = y - A x of one declared parameter and one effect, rows in ``N_FOLDS`` folds (one
    per mode), at its least-squares solution."""

    def __init__(self, y: np.ndarray, A: np.ndarray):
        self.A = A
        x = np.linalg.lstsq(A, y, rcond=None)[0]
        self.state = SimpleNamespace(r=y - A @ x)
        self.x = x

    def row_groups(self):
        return np.zeros(self.A.shape[0], int), np.repeat(np.arange(N_FOLDS), ROWS)

    def param_columns(self, state):
        return self.A[:, :1]

    def effect_columns(self, state, effects):
        return self.A[:, 1:2]


def _columns(rng) -> np.ndarray:
    return np.column_stack([np.ones(N_FOLDS * ROWS), rng.standard_normal(N_FOLDS * ROWS)])


def test_jackknife_matches_the_noise_when_the_folds_agree():
    rng = np.random.default_rng(3)
    A = _columns(rng)
    analytic = np.linalg.inv(A.T @ A)[1, 1]  # unit noise
    var = [jackknife_cov(res, res.state, ["e"], np.ones(1))[0, 0]
           for res in (_Linear(A @ [0.5, 2.0] + rng.standard_normal(A.shape[0]), A) for _ in range(400))]
    assert np.mean(var) == pytest.approx(analytic, rel=0.15)


def test_jackknife_shows_a_fold_that_disagrees():
    """One mode whose rows want another magnitude (a model error confined to it): the fit's noise
    covariance does not see it, the spread between the folds does."""
    rng = np.random.default_rng(4)
    A = _columns(rng)
    y = A @ [0.5, 2.0] + rng.standard_normal(A.shape[0])
    y[:ROWS] += 3.0 * A[:ROWS, 1]  # fold 0: the effect's column three units stronger
    res = _Linear(y, A)
    noise = np.sqrt(np.linalg.inv(A.T @ A)[1, 1])
    spread = np.sqrt(jackknife_cov(res, res.state, ["e"], np.ones(1))[0, 0])
    assert spread > 3.0 * noise
    bias = res.x[1] - 2.0  # what the bad fold does to the estimate
    assert abs(bias) <= 2.0 * spread < 10.0 * abs(bias)


def test_reported_parts_add_in_quadrature():
    w = np.array([1.0, 1.0])
    cov, jack = np.diag([1e-6, 1e-6]), np.diag([4e-6, 0.0])
    u = parts(0.01, w, cov, jack)
    assert u["noise"] == pytest.approx(np.sqrt(2e-6)) and u["across_folds"] == pytest.approx(2e-3)
    assert u["model_form"] == pytest.approx(MODEL_FORM * 0.01)
    assert u["total"] == pytest.approx(np.hypot(2e-3, MODEL_FORM * 0.01))
