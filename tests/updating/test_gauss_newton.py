"""The bounded Gauss-Newton's damped steps (:func:`pcbdyn.updating.gauss_newton.gauss_newton`): where the
Jacobian it is given makes the Gauss-Newton direction climb (finite differences of re-meshed models, a
far start), every halving of the step raises chi^2, while Marquardt's damped step turns towards
steepest descent, whose direction J^T r still descends."""

from __future__ import annotations

import numpy as np
import pytest

from pcbdyn.updating.gauss_newton import DAMPING, gauss_newton

#: the residual r(y) = b - y (rows data - prediction, true Jacobian I) and a Jacobian whose coupled
#: columns make J^-1 r point away from the minimum: J^-1 r . r < 0, while J^T r . r > 0
B = np.array([1.0, 0.1])
J_OFF = np.array([[1.0, 1.1], [1.1, 1.0]])


class _State:
    def __init__(self, r):
        self.r = r


def _fit(damping):
    return gauss_newton(lambda y: _State(B - y), lambda st: J_OFF, np.zeros(2), np.full(2, -10.0), np.full(2, 10.0),
                        np.ones(2), 1, lambda y: np.full(2, 1e-12), damping)


def test_a_step_the_halvings_cannot_take_is_taken_damped():
    gn_step = np.linalg.solve(J_OFF, B)  # the case: the given Jacobian's step climbs, halved or not
    assert gn_step @ B < 0.0 < (J_OFF.T @ B) @ B
    plain, damped = _fit(()), _fit(DAMPING)
    assert plain.chi2 == pytest.approx(B @ B, rel=1e-12)  # stalled where it started
    assert damped.chi2 < 0.8 * B @ B


def test_a_step_is_halved_in_turn_until_the_model_can_be_evaluated():
    """r = 1 - y with the model unsolvable beyond y = 0.3 (None): the steps tried are 1, 1/2, 1/4 of
    Gauss-Newton's, and the first evaluable one, 1/4, is taken."""
    def evaluate(y):
        return None if y[0] > 0.3 else _State(1.0 - y)

    gn = gauss_newton(evaluate, lambda st: np.ones((1, 1)), np.zeros(1), np.full(1, -10.0), np.full(1, 10.0),
                      np.ones(1), 1, lambda y: np.full(1, 1e-12))
    assert gn.y[0] == pytest.approx(0.25, abs=1e-12)


def test_a_converged_fit_tries_no_further_step():
    """A mildly nonlinear residual r(y) = b - (y + 0.01 y^3) in noise units, from y = 0 with twenty steps and
    a step tolerance nothing meets: the fit reaches the least-squares solution (to the statistical
    precision CHI2_TOL asks, 0.1 of a standard deviation, here 0.1 in y) and then stops instead of
    spending its remaining steps on round-off and its halvings; once it has converged its last
    Jacobian is the one it already made there."""
    b = np.array([3.0, 3.2, 2.9])
    calls = {"evaluate": 0, "jacobian": 0}

    def evaluate(y):
        calls["evaluate"] += 1
        st = _State(b - (y[0] + 0.01 * y[0] ** 3))
        st.y = float(y[0])
        return st

    def jacobian(st):
        calls["jacobian"] += 1
        return np.full((3, 1), 1.0 + 0.03 * st.y**2)

    gn = gauss_newton(evaluate, jacobian, np.zeros(1), np.full(1, -10.0), np.full(1, 10.0), np.ones(1), 20,
                      lambda y: np.full(1, 1e-15))
    roots = np.roots([0.01, 0.0, 1.0, -b.mean()])
    exact = roots.real[np.abs(roots.imag) < 1e-12][0]
    sigma = 1.0 / (np.sqrt(3.0) * (1.0 + 0.03 * exact**2))  # one standard deviation of y at unit noise
    assert abs(gn.y[0] - exact) < 0.1 * sigma
    assert calls["evaluate"] <= 4  # the start and a few Gauss-Newton steps (seven without the rule), not twenty
    assert calls["jacobian"] == calls["evaluate"]  # one per state stood on, none made twice
