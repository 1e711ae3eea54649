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
    cov, jack, place = np.diag([1e-6, 1e-6]), np.diag([4e-6, 0.0]), np.diag([0.0, 9e-6])
    u = parts(0.01, w, cov, jack, place)
    assert u["noise"] == pytest.approx(np.sqrt(2e-6)) and u["across_folds"] == pytest.approx(2e-3)
    assert u["place"] == pytest.approx(3e-3) and u["model_form"] == pytest.approx(MODEL_FORM * 0.01)
    assert u["total"] == pytest.approx(np.sqrt(4e-6 + 9e-6 + (MODEL_FORM * 0.01) ** 2))


@pytest.mark.parametrize("xy, wide", [((0.0733, 0.0836), False), ((0.005, 0.07), True)])
def test_a_mass_whose_place_the_modes_cannot_tell_has_a_wide_interval(xy, wide):
    """A 20 g mass between the nodes of the guided card, frequencies at 0.2 %, fitted at its point with
    the modulus: inside the card its place is known and leaves its magnitude known within a few
    percent (the place's share under 5 % of it, as the noise's is); 5 mm from the guide at x = 0, where the modes are linear in
    x and a mass m at x fits as m (x / x')^2 at x', the place's share is at least half the magnitude,
    and a fit 3 mm further in (a 2.8 times smaller mass) lies within its two standard deviations."""
    import scipy.sparse as sp

    from pcbdyn import diagnosis as dg
    from pcbdyn.diagnosis.moves import LocalMoves
    from pcbdyn.diagnosis.point_mass import MASS
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate
    from pcbdyn.diagnosis.uncertainty import place_cov
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import solve_modes
    from pcbdyn.testdata import MeasuredModes

    from diagnosis_plates import guided_card

    m = guided_card()
    layout = dg.from_model(m)
    home = dg.generate(layout, kinds=["point_mass"])[0]
    truth = MASS.at_point(layout, home, xy)
    f = solve_modes(dg.add_effect(m, truth, 0.020), n_modes=8).frequencies
    n = m.n_dof
    dK = assemble(guided_card(E=1.0), sets=["plate"])[0]
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(8, 0.002))],
                        lambda p: [guided_card(E=p[0])], lambda p, models: [[(dK, sp.csr_matrix((n, n)))]], n_params=1)
    fit = estimate(res, np.array([26e9]), [truth], [0.020], 8)
    cands = [truth]
    near = LocalMoves(layout, cands, 13.3e-3)
    cov = place_cov(res, fit.state, [truth], np.array([MASS.scale]), lambda j: [cands[i] for i in near(0)])
    place, noise = np.sqrt(cov[0, 0]), np.sqrt(fit.cov[-1, -1])
    if not wide:
        assert place < 0.05 * fit.values[0] and noise < 0.05 * fit.values[0]
        return
    assert place > 0.5 * fit.values[0]
    inner = estimate(res, fit.p, [MASS.at_point(layout, home, (xy[0] + 0.003, xy[1]))], fit.values, 8)
    assert abs(inner.values[0] - fit.values[0]) <= 2.0 * np.hypot(place, noise)
