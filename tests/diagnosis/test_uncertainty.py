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
    cov = place_cov(res, fit.state, [truth], np.array([MASS.scale]), lambda c: [cands[i] for i in near(0)])
    place, noise = np.sqrt(cov[0, 0]), np.sqrt(fit.cov[-1, -1])
    if not wide:
        assert place < 0.05 * fit.values[0] and noise < 0.05 * fit.values[0]
        return
    assert place > 0.5 * fit.values[0]
    inner = estimate(res, fit.p, [MASS.at_point(layout, home, (xy[0] + 0.003, xy[1]))], fit.values, 8)
    assert abs(inner.values[0] - fit.values[0]) <= 2.0 * np.hypot(place, noise)


def test_the_covariance_does_not_depend_on_the_units_of_the_columns():
    """A column 1e-9 the size of another (ln E beside a stiff spring in N/m) is still a column: the
    covariance is (J^T J)^-1 in any units, not a pseudo-inverse that drops the small one as rank."""
    from pcbdyn.updating.solvers import covariance

    rng = np.random.default_rng(5)
    J = rng.standard_normal((30, 2))
    r = rng.standard_normal(30)
    units = np.array([1.0, 1e-9])
    assert covariance(J * units, r) == pytest.approx(covariance(J, r) / np.outer(units, units), rel=1e-9)


def test_an_interval_from_a_symmetric_profile_is_the_covariance_s():
    """Given a profile that reaches two noise sigmas either way (a linear magnitude), the reported interval
    is the magnitude -+ twice the total standard deviation; open above where the profile is."""
    from pcbdyn.diagnosis.uncertainty import interval

    u = parts(0.01, np.ones(1), np.array([[1e-6]]), np.array([[4e-6]]), np.array([[9e-6]]))
    assert u["across_folds"] > u["noise"]  # the folds' part widens the profile's reach
    lo, hi = interval(0.01, u, (0.01 - 2.0 * u["noise"], 0.01 + 2.0 * u["noise"]))
    assert (lo, hi) == pytest.approx((0.01 - 2.0 * u["total"], 0.01 + 2.0 * u["total"]), rel=1e-12)
    assert interval(0.01, u, (0.0095, None))[1] is None
    assert interval(0.001, u, None, lower=0.0)[0] == 0.0  # no lower than the kind allows


@pytest.mark.parametrize("k_true", [3e4, 3e5, 3e7])
def test_the_profile_of_a_spring_opens_above_as_it_stiffens(k_true):
    """A spring to ground inside a cell of the guided card, frequencies with 0.2 % noise, fitted with
    the modulus; its 2-sigma interval by the chi^2 profile (:func:`profile_interval`): at 30 kN/m the
    frequencies are linear in k and the profile reaches the covariance's two sigmas either way (within
    20 %); at 300 kN/m the modes stiffen less with each newton, and it reaches further above than below;
    at 30 MN/m, beyond the kind's range, the fit stops at its bound (10 MN/m), where the covariance's
    interval excludes the truth and the profile stays open above."""
    import scipy.sparse as sp

    from pcbdyn import diagnosis as dg
    from pcbdyn.diagnosis.catalogue import kind
    from pcbdyn.diagnosis.fitting import UPPER
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate
    from pcbdyn.diagnosis.uncertainty import profile_interval
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import solve_modes
    from pcbdyn.testdata import MeasuredModes

    from diagnosis_plates import guided_card

    spring = kind("ground_spring")
    m = guided_card()
    layout = dg.from_model(m)
    truth = spring.at_point(layout, dg.generate(layout, kinds=["ground_spring"])[0], (0.0733, 0.0836))
    f = solve_modes(dg.add_effect(m, truth, k_true), n_modes=8).frequencies
    f = f * (1.0 + 0.002 * np.random.default_rng(0).standard_normal(f.size))
    n = m.n_dof
    dK = assemble(guided_card(E=1.0), sets=["plate"])[0]
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(8, 0.002))],
                        lambda p: [guided_card(E=p[0])], lambda p, models: [[(dK, sp.csr_matrix((n, n)))]], n_params=1)
    fit = estimate(res, np.array([26e9]), [truth], [min(k_true, 1e7)], 10)
    k, two = fit.values[0], 2.0 * np.sqrt(fit.cov[-1, -1])
    lo, hi = profile_interval(res, fit.state, [truth], 0)
    if k_true < 1e5:
        assert k - lo == pytest.approx(two, rel=0.2) and hi - k == pytest.approx(two, rel=0.2)
    elif k_true < 1e7:
        assert lo < k_true < hi and hi - k > 1.3 * (k - lo)
    else:
        assert k == pytest.approx(UPPER * spring.scale) and k + two < k_true
        assert hi is None and k_true > lo > 0.5 * k
