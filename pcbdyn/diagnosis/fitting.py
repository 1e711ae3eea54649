"""One fit of the declared parameters and the magnitudes of chosen effects to a residual, through
the updating engine's bounded Gauss-Newton (thesis ch. 4): what every step of a diagnosis runs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..updating.gauss_newton import gauss_newton
from .catalogue import jointly

#: magnitudes are bounded by this many times their kind's typical ``scale`` (a 1 kg mass or a
#: 1e7 N/m spring is no longer an effect a test setup hides; unbounded, a huge mass pins a node)
UPPER = 100.0
#: Gauss-Newton steps used to rank the shortlist (the winner is then fitted to convergence)
RANK_STEPS = 2


@dataclass
class Fit:
    """Declared parameters ``p`` [SI] and magnitudes ``values`` fitted, the residual's ``state``
    there and the covariance ``cov`` of (ln p, magnitudes); ``chi2_value``: the fit's chi^2 where
    the state is not kept (a trial fit run elsewhere)."""

    p: np.ndarray
    values: np.ndarray
    state: object
    cov: np.ndarray
    chi2_value: float | None = None

    @property
    def chi2(self) -> float:
        if self.state is None:
            return np.inf if self.chi2_value is None else self.chi2_value
        return self.state.chi2


def estimate(res, p0, cands, v0, steps: int, bounds=None, tol: float = 1e-5, param_columns=None,
             reduced=None, held=()) -> Fit:
    """The declared parameters (on a log scale, within ``bounds`` = (lower, upper) of p) and the
    magnitudes of ``cands`` fitted to the residual ``res`` by the updating engine's bounded Gauss-Newton
    (:func:`pcbdyn.updating.gauss_newton.gauss_newton`); ``cov`` is the covariance of (ln p,
    magnitudes). ``param_columns``: the parameters' columns held from an earlier state (a quick fit
    that ranks candidates need not re-derive the board's matrices at every step); ``reduced``: a
    :class:`.reanalysis.Reanalysis` that evaluates the states instead of full re-solves (quick fits
    that rank candidates). Magnitudes that break their kinds' joint test (:func:`.catalogue.jointly`:
    overlapping regions softened to no stiffness) are refused as a failed solve is. ``held``: [(candidate,
    magnitude)] in the model at fixed magnitudes, not fitted (a profile of one magnitude)."""
    p = np.asarray(p0, float)
    npar = p.size
    lo_v = np.array([c.spec.lower for c in cands], float)
    hi_v = UPPER * np.array([c.spec.scale for c in cands], float)
    scale = np.r_[np.ones(npar), [c.spec.scale for c in cands]]
    lo_p, hi_p = (np.full(npar, 0.0), np.full(npar, np.inf)) if bounds is None else bounds
    lo_p = np.maximum(lo_p, 1e-6 * np.abs(p))  # ln p: a parameter may shrink a millionfold, not vanish
    with np.errstate(divide="ignore"):
        lower, upper = np.r_[np.log(lo_p), lo_v], np.r_[np.log(hi_p), hi_v]

    run = res if reduced is None else reduced
    admissible = jointly(cands)
    fixed = [c for c, _ in held]
    fixed_values = np.array([v for _, v in held], float)

    def evaluate(y):
        if not admissible(y[npar:]):
            return None
        try:
            st = run.evaluate(np.exp(y[:npar]), list(cands) + fixed, np.r_[y[npar:], fixed_values])
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):
            return None
        # a paired model mode that does not move at the points has no shape to compare
        return st if np.isfinite(st.r).all() else None

    def step_tol(y):
        return tol * np.r_[np.ones(npar), np.maximum(np.abs(y[npar:]), scale[npar:])]

    y0 = np.r_[np.log(p), np.clip(np.asarray(v0, float), lo_v, hi_v)]
    gn = gauss_newton(evaluate, lambda st: _jacobian(res, st, cands, npar, param_columns, run), y0, lower, upper,
                      scale, steps, step_tol)
    return Fit(np.exp(gn.y[:npar]), gn.y[npar:], gn.state, gn.cov)


def _jacobian(res, st, cands, npar, param_columns=None, run=None):
    cols = [res.param_columns(st) if param_columns is None else param_columns] if npar else []
    if cands:
        cols.append((run or res).effect_columns(st, cands))
    return np.hstack(cols) if cols else np.zeros((res.n_rows, 0))


def pattern_search(res, others: list, x, build, fit: Fit, step: float, levels: int, bounds=None, reduced=None,
                   param_columns=None):
    """(x, fit) of effects whose geometry is the coordinates ``x`` [m] (a centre, a line's ends), moved
    one coordinate at a time by ``step`` either way while chi^2 drops, then by half that, ``levels``
    step sizes in all; ``build(x)``: the candidates at ``x`` (None off the structure), fitted with
    ``others`` by quick fits from ``fit`` (on ``reduced``, a :class:`.reanalysis.Reanalysis`, where
    given, with the parameters' columns ``param_columns`` of its state: the fit returned is then that
    reduced one). A mass's place is a geometric parameter the linear fit of magnitudes cannot move
    (what :mod:`.bodies` and :mod:`.mass_lines` walk)."""
    x = np.asarray(x, float).copy()
    for s in step / 2.0 ** np.arange(levels):
        moved = True
        while moved:
            moved = False
            for k, d in ((k, d) for k in range(x.size) for d in (s, -s)):
                trial_x = x.copy()
                trial_x[k] += d
                made = build(trial_x)
                if made is None:
                    continue
                trial = estimate(res, fit.p, others + made, fit.values, RANK_STEPS, bounds, param_columns=param_columns,
                                 reduced=reduced)
                if trial.state is not None and trial.chi2 < fit.chi2 * (1.0 - 1e-6):
                    x, fit, moved = trial_x, trial, True
                    break
    return x, fit
