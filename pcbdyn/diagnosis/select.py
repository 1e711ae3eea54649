"""First selection of the effects that explain frequency residuals (issue 7, step 5): greedy
forward selection over the candidates' sensitivity columns, each choice followed by a nonlinear
estimate of the chosen magnitudes, stopped by an information criterion.

Rows are the paired modes, weighted by the frequency noise: r_i = (f_test,i - f_i) / (sigma f_test,i)
and a_ij = (df_i / dp_j) s_j / (sigma f_test,i) (s_j: the kind's typical magnitude, so that
columns of different units compare), so that chi^2 = |r|^2 counts residual in units of
noise. Step k takes the column that removes the most chi^2 once the columns already chosen are
projected out (the cos^2 criterion of thesis eqs. 5.51-5.54 applied to the residual) among
those whose estimated value is physical (``lower`` of its kind), confirmed on a shortlist by
re-estimating all chosen magnitudes by Gauss-Newton with full re-solves, within
[lower, UPPER * scale] (the effects are linear in K and M, the frequencies are not). A new effect is kept only if it lowers
    chi^2 + k * max(ln n, q)
(n modes, k effects), q being the chi^2 (1 degree of freedom) quantile exceeded with probability
ALPHA / P (P candidates): the best of P noise-only columns removes less than q with probability
1 - ALPHA (Bonferroni), so noise alone does not make an effect; ln n is BIC's term. After each
addition an earlier effect that the others make redundant is dropped (backward check).
Modes are paired by order here; the diagnose command must pair them by MAC first.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.stats import chi2 as chi2_dist

from ..fe.modal import solve_modes
from .catalogue import add_effect, frequency_columns

#: magnitudes are bounded by this many times their kind's typical ``scale`` (a 1 kg mass or a
#: 1e7 N/m spring is no longer an effect a test setup hides; unbounded, a huge mass pins a node)
UPPER = 100.0
#: probability that noise alone makes one of the candidates look like an effect (family-wise)
ALPHA = 0.01
#: Gauss-Newton steps used to rank the shortlist (the winner is then fitted to convergence)
RANK_STEPS = 2


@dataclass
class Selection:
    """``chosen``: candidate indices in the order found; ``values``: their magnitudes (SI);
    ``chi2[s]``, ``criterion[s]``: after step s (s = 0: the model as given; a step adds one
    effect and may drop an earlier one);
    ``frequencies``: the model's frequencies with the chosen effects."""

    chosen: list = field(default_factory=list)
    values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    chi2: list = field(default_factory=list)
    criterion: list = field(default_factory=list)
    frequencies: np.ndarray = field(default_factory=lambda: np.zeros(0))


def with_effects(model, candidates, values):
    """``model`` carrying each candidate at its value (zero values are left out)."""
    for c, v in zip(candidates, values):
        if v != 0.0:
            model = add_effect(model, c, float(v))
    return model


def penalty(n_obs: int, n_candidates: int, alpha: float = ALPHA) -> float:
    """Criterion cost of one more effect: max(ln n, chi^2_1 quantile at 1 - alpha / P)."""
    return max(np.log(n_obs), float(chi2_dist.isf(alpha / max(n_candidates, 1), 1)))


def _residual(model, f_test, sigma, n):
    modes = solve_modes(model, n_modes=n)
    f = modes.frequencies[:n]
    return modes, f, (f_test - f) / (sigma * f_test)


def _estimate(model, cands, v0, f_test, sigma, n, steps, tol=1e-6):
    """Gauss-Newton on the magnitudes of ``cands`` (bounded below by their kinds' ``lower``)."""
    lower = np.array([c.spec.lower for c in cands])
    upper = UPPER * np.array([c.spec.scale for c in cands])
    v = np.clip(np.asarray(v0, dtype=float), lower, upper)
    for _ in range(steps):
        current = with_effects(model, cands, v)
        modes, _, r = _residual(current, f_test, sigma, n)
        J = frequency_columns(current, modes, cands)[:n] / (sigma * f_test)[:, None]
        dv = np.linalg.lstsq(J, r, rcond=None)[0]
        v_new = np.clip(v + dv, lower, upper)
        done = np.all(np.abs(v_new - v) <= tol * np.maximum(np.abs(v), [c.spec.scale for c in cands]))
        v = v_new
        if done:
            break
    modes, f, r = _residual(with_effects(model, cands, v), f_test, sigma, n)
    return v, f, float(r @ r), modes


def forward_select(model, candidates, f_test, sigma: float, max_effects: int = 3, newton_steps: int = 8,
                   shortlist: int = 3, alpha: float = ALPHA) -> Selection:
    """Effects among ``candidates`` explaining measured frequencies ``f_test`` [Hz] (paired in order
    with the model's first len(f_test) elastic modes), relative noise ``sigma`` (e.g. 0.002).
    Each step fits the ``shortlist`` best columns of every kind by the linear score with re-solves
    and keeps the one of least chi^2 (a spring's or an edge's effect on the frequencies saturates, so the linear
    score alone under-rates large ones)."""
    f_test = np.asarray(f_test, dtype=float)
    if not sigma > 0:
        raise ValueError(f"sigma (relative frequency noise) must be > 0, got {sigma}")
    n = f_test.size
    pen = penalty(n, len(candidates), alpha)
    modes, f, r = _residual(model, f_test, sigma, n)
    sel = Selection(chi2=[float(r @ r)], criterion=[float(r @ r)], frequencies=f)
    current = model
    kinds = np.array([c.kind for c in candidates])
    scale = np.array([c.spec.scale for c in candidates])  # columns per typical magnitude: comparable units
    for _ in range(max_effects):
        if sel.chi2[-1] <= pen:  # chi^2 >= 0: one more effect cannot lower the criterion
            break
        A = frequency_columns(current, modes, candidates)[:n] * scale / (sigma * f_test)[:, None]
        if sel.chosen:
            Q, _ = np.linalg.qr(A[:, sel.chosen])
            A_p, r_p = A - Q @ (Q.T @ A), r - Q @ (Q.T @ r)
        else:
            A_p, r_p = A, r
        norm2 = np.einsum("ij,ij->j", A_p, A_p)
        ok = norm2 > 1e-12 * norm2.max()
        value = np.where(ok, A_p.T @ r_p / np.where(ok, norm2, 1.0), 0.0) * scale
        gain = np.where(ok, value**2 * norm2, -np.inf)
        lower = np.array([c.spec.lower for c in candidates])
        gain[value < lower] = -np.inf  # an effect of unphysical sign cannot be the answer
        gain[sel.chosen] = -np.inf
        order = _shortlist(gain, kinds, shortlist)
        if not order.size:
            break
        fits = [_estimate(model, [candidates[i] for i in sel.chosen + [j]], np.r_[sel.values, value[j]], f_test, sigma,
                          n, RANK_STEPS) for j in order]
        best = int(np.argmin([fit[2] for fit in fits]))
        idx = sel.chosen + [int(order[best])]
        v, f_new, chi2, modes_new = _estimate(model, [candidates[i] for i in idx], fits[best][0], f_test, sigma, n,
                                              newton_steps)
        if chi2 + len(idx) * pen >= sel.criterion[-1]:
            break
        idx, v, f_new, chi2, modes_new = _prune(model, candidates, idx, v, f_new, chi2, modes_new, f_test, sigma,
                                                n, newton_steps, pen)
        sel.chosen, sel.values, sel.frequencies = idx, v, f_new
        sel.chi2.append(chi2)
        sel.criterion.append(chi2 + len(idx) * pen)
        current = with_effects(model, [candidates[i] for i in idx], v)
        modes, r = modes_new, (f_test - f_new) / (sigma * f_test)
    return sel


def _shortlist(gain, kinds, per_kind: int) -> np.ndarray:
    """The ``per_kind`` best finite-gain columns of every kind."""
    out = []
    for k in np.unique(kinds):
        idx = np.flatnonzero((kinds == k) & np.isfinite(gain))
        out.append(idx[np.argsort(-gain[idx])[:per_kind]])
    return np.concatenate(out) if out else np.zeros(0, dtype=np.int64)


def _prune(model, candidates, idx, v, f, chi2, modes, f_test, sigma, n, steps, pen):
    """Backward check after each addition: drop an earlier effect whenever the others, re-estimated
    without it, reach a lower criterion (greedy choices made before the right effect was in)."""
    while len(idx) > 1:
        best = None
        for drop in range(len(idx) - 1):
            keep = [i for t, i in enumerate(idx) if t != drop]
            trial = _estimate(model, [candidates[i] for i in keep], np.delete(v, drop), f_test, sigma, n, steps)
            if trial[2] + len(keep) * pen < chi2 + len(idx) * pen and (best is None or trial[2] < best[1][2]):
                best = (keep, trial)
        if best is None:
            break
        idx, (v, f, chi2, modes) = best[0], best[1]
    return idx, v, f, chi2, modes
