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
