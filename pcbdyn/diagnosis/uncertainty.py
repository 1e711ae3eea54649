"""The uncertainty reported with each effect found (issue 26): what the fit's covariance says is only
the noise's share, and the model's own errors (its mesh, its plate theory, what another FE code would
do differently) bias a magnitude far beyond it (a 10 g mass once reported as 11.44 +- 0.09 g). So the
reported standard deviation combines, in quadrature,

- the larger of the fit's covariance (:func:`pcbdyn.updating.solvers.covariance`: the noise, rows
  weighted as in thesis eq. 4.28, propagated through the sensitivities) and a jackknife over the
  held-out folds of :func:`.held_out.held_out_share` (one configuration, or one mode, left out at a
  time, to first order at the fitted state): when the modes or configurations disagree on a
  magnitude, the spread between them is the better measure;
- what the effects' places leave open (:func:`place_cov`): the magnitudes fitted with the places as
  further unknowns, to first order. A fit at a fixed place says how well the size is known there, not
  how well it is known; where the data trade one for the other the second is far wider (a mass beside
  a hinged edge: the modes are linear in the distance from it there, and they feel m x^2, so a mass
  at half the distance and four times the size fits as well; a region's extent against its change);
- a model-form budget, a fixed share of the magnitude (:data:`MODEL_FORM`), measured on the
  diagnosis bench: the magnitudes found from tests meshed four times finer than the model and from
  tests computed by another FE code (OpenSees).

The parts are kept apart in the report (``uncertainty_parts``) so that a user sees which one rules.
"""

from __future__ import annotations

import numpy as np

from ..updating.solvers import covariance
from .held_out import fit_without, folds
from .reanalysis import Reanalysis

#: the model-form budget: one standard deviation as a share of the magnitude, for every reported type.
#: Calibrated with ``benchmarks/bench_coverage.py --calibrate`` on the bench and hold-out cases other
#: than the three whose repeats check the coverage: half the 90th percentile of the relative errors
#: of the magnitudes found (18 effects, errors 0.1 to 18.5 %; per type there are too few to tell the
#: types apart), so that two standard deviations cover nine in ten
MODEL_FORM = 0.07


def jackknife_cov(res, state, effects, scale) -> np.ndarray:
    """Jackknife covariance (k, k) of the magnitudes (SI) of ``effects`` (``scale``: their columns'
    scales) over the held-out folds, each fold's fit taken to first order at ``state`` (the fitted
    state, where the residual is orthogonal to the columns: the shift of a refit without the fold is
    one least-squares solve). Zeros when there is one fold."""
    k = len(effects)
    groups = folds(res)
    values = np.unique(groups)
    if k == 0 or values.size < 2:
        return np.zeros((k, k))
    J = np.hstack([res.param_columns(state), res.effect_columns(state, effects) * scale])
    shifts = [fit_without(J, state.r, groups == f)[-k:] * scale for f in values]
    d = np.array(shifts) - np.mean(shifts, axis=0)
    g = values.size
    return (g - 1) / g * d.T @ d


def place_cov(res, state, effects, scale, neighbours) -> np.ndarray:
    """Covariance (k, k) [SI] that the places of ``effects`` (fitted at ``state``; ``scale``: their
    columns' scales) add to their magnitudes (module doc): the magnitudes' covariance
    (:func:`pcbdyn.updating.solvers.covariance`) with a column per move of an effect to each of
    ``neighbours(j)`` (candidates one step of the local search from effect j: the residual's change at
    the same magnitudes, on the reanalysis of ``state``) less that without them. Zeros where no
    effect moves."""
    k = len(effects)
    if k == 0:
        return np.zeros((0, 0))
    rx = Reanalysis(res, state)
    r0 = rx.evaluate(state.p, effects, state.values).r
    G = []
    for j in range(k):
        try:
            moved = neighbours(j)
        except ValueError:  # no place beside it on this mesh (a model error, a probe off the shell)
            continue
        for n in moved:
            try:
                r = rx.evaluate(state.p, effects[:j] + [n] + effects[j + 1:], state.values).r
            except (ValueError, ArithmeticError, np.linalg.LinAlgError):
                continue
            if r.shape == r0.shape and np.isfinite(r).all():
                G.append(r - r0)
    if not G:
        return np.zeros((k, k))
    J = np.hstack([res.param_columns(state), res.effect_columns(state, effects) * scale])
    m = slice(J.shape[1] - k, J.shape[1])
    grown = covariance(np.column_stack([J] + G), state.r)[m, m] - covariance(J, state.r)[m, m]
    return np.outer(scale, scale) * grown


def parts(magnitude: float, w: np.ndarray, cov: np.ndarray, cov_jack: np.ndarray, cov_place: np.ndarray) -> dict:
    """The reported standard deviation of the combination ``w`` of magnitudes and its parts: ``noise``
    (fit covariance ``cov``), ``across_folds`` (jackknife ``cov_jack``), ``place`` (``cov_place``,
    :func:`place_cov`), ``model_form`` (:data:`MODEL_FORM` times the magnitude)."""
    noise, across, place = (float(np.sqrt(max(w @ c @ w, 0.0))) if c.size else 0.0 for c in (cov, cov_jack, cov_place))
    form = MODEL_FORM * abs(magnitude)
    return {"total": float(np.sqrt(max(noise, across) ** 2 + place**2 + form**2)), "noise": noise,
            "across_folds": across, "place": place, "model_form": form}
