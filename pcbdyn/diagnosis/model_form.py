"""What the model's form leaves between its frequencies and a tested board's, apart from any
effect it lacks: the mesh (corrected by Richardson extrapolation, the rest uncertain) and the
plate theory (Mindlin shells with a guessed transverse shear stiffness against the Kirchhoff limit,
which other codes and stiff-cored boards follow). Both are estimated on the model itself, on
meshes finer than its own; the plate theory's share is fitted last, with the effects found
(:func:`fit_plate_share`), so that what one FE code or another would say of the same board is
neither taken for an effect nor left in the error reported after."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..correlation.mac import mac, paired_mac
from ..problems.error_budget import richardson
from ..updating.solvers import covariance
from .fitting import estimate
from .selection import ALPHA, adopt, penalty, worth

#: a mode is resolved by the model's mesh when the twice finer mesh changes its shape at the
#: points by less than this (sqrt(1 - MAC)): only then is its frequency change an O(h^2) error
RESOLVED_SHAPE_CHANGE = 0.02
#: how many times the mesh is halved at most to correct the model's frequencies for it
MESH_LEVELS = 2


def pair(solved, ob, u_prev, k_prev):
    """(frequencies, shapes at the points, mode indices, shape change sqrt(1 - MAC)) of the modes
    ``solved`` (:class:`.finer.Solved`) paired by MAC at the points with the shapes ``u_prev`` (by
    index ``k_prev`` when there are no measured shapes: no change can be told, it is inf)."""
    if ob.shapes is None:
        k = np.minimum(k_prev, solved.f.size - 1)
        return solved.f[k], None, k, np.full(k.size, np.inf)
    k = mac(u_prev, solved.U).argmax(axis=1)
    U = solved.U[:, k]
    return solved.f[k], U, k, np.sqrt(np.clip(1.0 - paired_mac(U, u_prev), 0.0, None))


def discretisation(finer, ob, coarse_state):
    """(frequency correction factor, its relative uncertainty, relative shape error, resolved) per
    paired mode. ``finer``: the model's modes on meshes twice, four times, ... as fine
    (:class:`.finer.Solved`), taken one after the other while some mode is not yet resolved (modes
    paired by MAC at the points, level to level).
    A mode resolved between two levels (:data:`RESOLVED_SHAPE_CHANGE`) is corrected by Richardson
    extrapolation from them (:func:`pcbdyn.problems.error_budget.richardson`), whose own error (a
    third of the step) stays as noise; a mode no level resolves (or with no shapes to
    tell) takes the finest frequency, the last step counted as noise. The shape error is 4/3 of
    the change from the model's mesh to the next."""
    f0 = coarse_state.f_a / ob.f_scale
    f_prev, u_prev, k_prev = f0, coarse_state.u, coarse_state.pairs
    scale, sigma = np.ones(f0.size), np.zeros(f0.size)
    resolved, todo, ds = np.zeros(f0.size, bool), np.ones(f0.size, bool), None
    for solved in finer:
        f, U, k, change = pair(solved, ob, u_prev, k_prev)
        ok = todo & (change <= RESOLVED_SHAPE_CHANGE)
        f_conv, _, left = richardson(f_prev, f)
        scale = np.where(ok, f_conv / f0, np.where(todo, f / f0, scale))
        sigma = np.where(todo, np.where(ok, left, np.abs(f - f_prev)) / f0, sigma)
        resolved |= ok
        todo &= ~ok
        if ds is None:
            ds = np.where(np.isfinite(change), 4.0 / 3.0 * change, 0.0)
        if not todo.any():
            break
        f_prev, u_prev, k_prev = f, U, k
    return scale, sigma, ds, resolved


def kirchhoff_shift(fine, limit, ob, coarse_state) -> np.ndarray:
    """Relative frequency change per paired mode from ``fine`` (the modes on the finest mesh of
    :func:`discretisation`) to ``limit`` (the same mesh with the shells' transverse shear made
    rigid: the Kirchhoff limit, :data:`pcbdyn.problems.error_budget.KIRCHHOFF_SHEAR`). The gap grows as the mesh resolves
    the shear boundary layer at free edges (about 1 % on the twisting modes of a 2.8 mm card at a
    quarter of its model's mesh, half that at the model's mesh), so it is measured where the
    frequencies are corrected to."""
    f, U, k, _ = pair(fine, ob, coarse_state.u, coarse_state.pairs)
    fk, _, _, _ = pair(limit, ob, coarse_state.u if U is None else U, k)
    return fk / f - 1.0


def fit_plate_share(res, candidates, sel, shifts, sigma_f, bounds=None, alpha: float = ALPHA, rounds: int = 2):
    """(``sel`` re-estimated, theta, its standard deviation, ``res`` as below): theta in [0, 1] scales each
    observation's Kirchhoff ``shifts`` into its frequencies (0: the declared Mindlin shells, 1: the
    Kirchhoff limit), fitted with the declared parameters and the effects of ``sel``: linearised,
    then the rest re-estimated by Gauss-Newton, in noise units ``sigma_f`` (per observation, the
    frequency sigmas without the plate theory's gap, which the search counted as noise). Theta
    moves from 0 only where its chi^2 drop is significant (:func:`.selection.worth`, the penalty of
    one more column): on data of the model's own form it stays 0. Either way the data have now
    bounded it, so the frequency sigmas keep only its uncertainty's part of the gap, and ``sel``
    is re-estimated with them, in the residual of observations with those sigmas and with ``f_scale``
    carrying theta."""
    chosen = [candidates[i] for i in sel.chosen]
    scale = np.array([c.spec.scale for c in chosen], float)
    res = res.on([replace(ob, sigma_f=s) for ob, s in zip(res.observations, sigma_f)])
    fit = estimate(res, sel.p, chosen, sel.values, 0, bounds)
    theta, var_theta = 0.0, 1.0
    for _ in range(rounds):
        st = fit.state
        held = np.hstack([res.param_columns(st), res.effect_columns(st, chosen) * scale])
        col = np.concatenate([np.r_[cs.f_a * d / (1.0 + theta * d) / (ob.sigma_f * ob.f), np.zeros(cs.r.size - ob.f.size)]
                              for ob, cs, d in zip(res.observations, st.configs, shifts)])
        J = np.column_stack([held, col])
        x = np.linalg.lstsq(J, st.r, rcond=None)[0]
        var_theta = min(1.0, covariance(J, st.r)[-1, -1])
        x0 = np.linalg.lstsq(held, st.r, rcond=None)[0] if held.shape[1] else np.zeros(0)
        step = float(np.clip(theta + x[-1], 0.0, 1.0)) - theta
        e1, e0 = st.r - J[:, :-1] @ x[:-1] - col * step, st.r - held @ x0
        if abs(step) < 1e-3 or not worth(float(e0 @ e0), float(e1 @ e1), res.n_rows, J.shape[1], penalty(res.n_rows, 1, alpha)):
            break
        moved = _shifted(res, shifts, theta, theta + step)
        trial = estimate(moved, fit.p, chosen, fit.values, 8, bounds)
        if trial.state is None or trial.chi2 >= fit.chi2:  # the linear step did not pay
            break
        res, theta, fit = moved, theta + step, trial
    res = res.on([replace(ob, sigma_f=np.sqrt(s**2 + var_theta * d**2))
                  for ob, s, d in zip(res.observations, sigma_f, shifts)])
    fit = estimate(res, fit.p, chosen, fit.values, 8, bounds)
    return adopt(sel, sel.chosen, fit, penalty(res.n_rows, len(candidates), alpha)), theta, float(np.sqrt(var_theta)), res


def _shifted(res, shifts, old: float, new: float):
    """``res`` of its observations with their frequency factors moved from plate theory share ``old`` to
    ``new``."""
    return res.on([replace(ob, f_scale=ob.f_scale * (1.0 + new * d) / (1.0 + old * d))
                   for ob, d in zip(res.observations, shifts)])
