"""Bounded Gauss-Newton on a residual in units of noise (thesis ch. 4 with the bounds of eqs.
4.44-4.48): the nonlinear fit of parameters whose residual is re-solved at every trial, with each step
halved while it does not lower chi^2 = |r|^2 (and, where a caller asks, damped as Levenberg-Marquardt's
where no halving does). Diagnosis estimates declared parameters (on a log scale), effect magnitudes and
ribs' geometry with it; the bounded step and the covariance are the updating solvers'.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import chain

import numpy as np

from .solvers import bounded_lsq, covariance

#: how many times a step that raises chi^2 is halved before the fit stops
HALVINGS = 4
#: relative rise of chi^2 a step may make and still be taken (round-off)
RISE_TOL = 1e-9
#: a step whose linear model lowers chi^2 by less than this (noise units) is not tried: the fit has
#: converged, since such a step moves the variables by about sqrt(CHI2_TOL) = 0.1 of their standard
#: deviations (chi^2 drop = |J dy|^2 to first order). Without it a converged fit spent its remaining
#: steps on steps that raised chi^2 by round-off and their halvings: on dev seed 10 the winner's
#: 8-step fit reached chi^2 4138.886 in its 4th evaluation and took five more to gain 0.002
CHI2_TOL = 1e-2
#: ... and by less than this share of chi^2 too: where the data fit to far below their stated noise (a
#: case without noise) the absolute rule alone would stop a fit well short of its solution
CHI2_REL = 1e-5
#: Marquardt's damping factors (on the columns scaled to unit length) that :func:`gauss_newton` may try, in
#: turn, where even the halved step does not lower chi^2: steps that turn from Gauss-Newton's towards
#: steepest descent, for a start far from the minimum of a strongly nonlinear residual
DAMPING = (1e-2, 1e-1, 1.0, 10.0)


def taken(chi2_new: float, chi2_now: float) -> bool:
    """Whether a trial of ``chi2_new`` replaces the state of ``chi2_now`` (:func:`gauss_newton`'s rule)."""
    return chi2_new <= chi2_now * (1 + RISE_TOL)


@dataclass
class GaussNewton:
    """``y``: the variables found; ``state``: the residual's state there (None when even the start
    could not be evaluated); ``cov``: the covariance of ``y`` from the last Jacobian."""

    y: np.ndarray
    state: object
    cov: np.ndarray

    @property
    def chi2(self) -> float:
        return np.inf if self.state is None else float(self.state.r @ self.state.r)


def gauss_newton(evaluate, jacobian, y0, lower, upper, scale, steps: int, step_tol, damping=()) -> GaussNewton:
    """Fit ``y`` from ``y0`` within [lower, upper].

    ``evaluate(y)``: the state at ``y`` (with ``r``, the residual rows in noise units), or None where
    the model cannot be evaluated; ``jacobian(state)``: dr/dy (n_rows, n_y) there (sign: the rows are
    data - prediction, so the step solves J dy = r); ``scale`` (n_y,): typical sizes of the variables,
    which condition the step; ``step_tol`` (n_y,): a step smaller than this in every variable ends the
    fit, and so does one whose linear model gains less than both :data:`CHI2_TOL` and :data:`CHI2_REL` of
    chi^2. At most ``steps`` steps; a step that raises chi^2 is halved up to :data:`HALVINGS` times, and where
    that fails, the steps damped by each of ``damping`` (Levenberg-Marquardt; e.g. :data:`DAMPING`) are tried."""
    y = np.asarray(y0, float)
    lower, upper, scale = (np.asarray(v, float) for v in (lower, upper, scale))
    st = evaluate(y)
    if st is None:
        return GaussNewton(y, None, np.zeros((0, 0)))
    chi2 = float(st.r @ st.r)
    J_st = None  # dr/dy at st, where made
    for _ in range(steps):
        J_st = jacobian(st)
        J = J_st * scale
        if J.shape[1] == 0:
            break
        lo, hi = np.minimum((lower - y) / scale, 0.0), np.maximum((upper - y) / scale, 0.0)
        u = bounded_lsq(J, st.r, lo, hi)
        if chi2 - float(np.sum((st.r - J @ u) ** 2)) < min(CHI2_TOL, CHI2_REL * chi2):
            break
        full = u * scale
        halved = (full * 0.5**k for k in range(HALVINGS))
        damped = (_damped(J, st.r, lo, hi, mu) * scale for mu in damping)
        for dy in chain(halved, damped):
            y_new = np.clip(y + dy, lower, upper)
            trial = evaluate(y_new)
            if trial is not None and taken(float(trial.r @ trial.r), chi2):
                break
        else:
            break
        small = np.all(np.abs(dy) <= step_tol(y))
        y, st, chi2, J_st = y_new, trial, float(trial.r @ trial.r), None
        if small:
            break
    J = jacobian(st) if J_st is None else J_st
    return GaussNewton(y, st, covariance(J, st.r) if J.shape[1] else np.zeros((0, 0)))


def _damped(J, r, lo, hi, mu: float) -> np.ndarray:
    """The step of (J^T J + mu diag(J^T J)) dy = J^T r (Marquardt) within [lo, hi] (``lo`` <= 0 <= ``hi``),
    in ``J``'s variables."""
    norms = np.linalg.norm(J, axis=0)
    d = np.where(norms > 0, norms, 1.0)
    return bounded_lsq(J / d, r, lo * d, hi * d, ridge=np.sqrt(mu)) / d
