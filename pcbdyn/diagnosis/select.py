"""Selection and estimation of the effects that explain a residual (issue 7, step 5): greedy forward
selection over the candidates' sensitivity columns, each choice confirmed by a nonlinear estimate
of the chosen magnitudes together with the declared parameters, stopped by an information
criterion.

The residual (:class:`.residual.ModalResidual`) is in units of noise, so chi^2 = |r|^2. Step k
projects out the columns of the declared parameters and of the effects already chosen and scores
every candidate by the chi^2 its column removes (the cos^2 criterion of thesis eqs. 5.51-5.54
applied to the residual), among those whose estimated value is physical (``lower`` of its kind).
The best ``shortlist`` of every kind are re-estimated nonlinearly (a spring's effect on the
frequencies saturates, so the linear score alone under-rates large ones; :class:`.scan.Ranking`: quick
fits on a reanalysis of the state, those that could be best with full re-solves) and the least criterion
(below) wins; of the kinds that saturate, so do the ``shortlist`` best at large magnitudes among more
of their candidates (:func:`.scan.saturated`). The two halves of a body at one place (a heat sink's
stiffness and mass, a bracket's mass and spring: :mod:`.halves`) are also tried as one addition,
which pays two penalties. Magnitudes stay within [lower, UPPER * scale], declared parameters within
their bounds.

A new effect is kept only if its chi^2 drop exceeds the penalty
    q = max(ln n, chi^2_1 quantile exceeded with probability ALPHA / P)
(n rows, P candidates: the best of P noise-only columns removes less than q with probability
1 - ALPHA, Bonferroni; ln n is BIC's term), both in the stated noise units and in units of the
variance left after the fit, chi^2 / (n - k): noise or model error larger than stated must not
turn into effects; and it must predict data it was not fitted to (:mod:`.held_out`: left-out
configurations, or modes), so that a model error confined to one configuration or mode is not taken
for an effect; an addition worth its penalty that the held-out folds refuse, of a kind whose candidates
lie on a grid coarser than the mesh (``coarse``: regions), is first walked to where it fits best and
tested there (a patch of the coarse grid beside a real region predicts it badly). Where the
trial that fits best is one that only the screen of saturating kinds or the bodies brought in and it
is refused, the next best is weighed: they must not hide what the linear shortlist found (a bar on a
card in guides, behind a guide's stiffness or a heat sink refused). Where a step keeps nothing and the
chi^2 left exceeds the noise, the bodies with a spring are once tried at a grid of magnitudes on the
reanalysis (:func:`.scan.resonant`: a bracket whose own mode falls among the structure's), and such a body
that both first-order predictions refuse is weighed by refits of the folds (:func:`.held_out.refit_predicts`),
as is a body's two halves from the linear shortlist, each half then refitted beside the other.
After each addition an earlier effect that the others make redundant is dropped (backward check).
"""

from __future__ import annotations

import numpy as np

from .catalogue import kind, moved_value
from .fitting import Fit, estimate
from .halves import Halves, bodies, body_moves, per_kind, together
from .held_out import predicts, refit_predicts, secant
from .reanalysis import Reanalysis
from .scan import Ranking, Runner, resonant, saturated, worth_full
from .selection import ALPHA, Selection, adopt, penalty, worth


def search(res, candidates, p0=(), bounds=None, max_effects: int = 3, newton_steps: int = 8, shortlist: int = 3,
           alpha: float = ALPHA, base: Fit | None = None, runner: Runner | None = None, held=(),
           without: float | None = None, moves=None) -> Selection:
    """Effects among ``candidates`` that explain the residual ``res`` (:class:`.residual.ModalResidual`)
    beyond the declared parameters (initial values ``p0``, ``bounds``) and the effects ``held``
    (candidate indices the data demand before any search: a support, :mod:`.support`); ``base``:
    the fit of the declared parameters and the held effects when already made, or the state the search
    starts from; ``without``: the least chi^2 without a new effect where ``base`` is not that fit (a
    search from the declared values), which every addition must then beat; ``runner``: where the
    shortlist's trial fits run (:mod:`.scan`); ``moves``: a :class:`.moves.LocalMoves` that walks an
    addition of a ``coarse`` kind worth its penalty but refused by the held-out folds before it is
    refused (:func:`_walked`).
    ``max_effects`` counts the held effects."""
    p0 = np.asarray(p0, float)
    n = res.n_rows
    pen = penalty(n, len(candidates), alpha)
    held = list(held)
    fit = base or estimate(res, p0, [candidates[i] for i in held], np.zeros(len(held)), newton_steps, bounds)
    sel = adopt(Selection(), held, fit, pen)
    if without is not None and without < sel.chi2[0]:
        sel.chi2[0], sel.criterion[0] = without, without + len(held) * pen
    halves, resonant_tried = Halves(candidates), False
    for _ in range(max_effects - len(held)):
        if sel.chi2[-1] <= pen:  # chi^2 >= 0: one more effect cannot lower the criterion
            break
        kinds = np.array([c.kind for c in candidates])  # again each step: a walk appends candidates
        scale = np.array([c.spec.scale for c in candidates])
        lower = np.array([c.spec.lower for c in candidates])
        st = fit.state
        A = res.effect_columns(st, candidates) * scale
        P = res.param_columns(st)
        held = np.hstack([P, res.effect_columns(st, [candidates[i] for i in sel.chosen]) * scale[sel.chosen]])
        Q = orth(held)
        A_p, r_p = A - Q @ (Q.T @ A), st.r - Q @ (Q.T @ st.r)
        norm2 = np.einsum("ij,ij->j", A_p, A_p)
        ok = norm2 > 1e-12 * norm2.max()
        value = np.where(ok, A_p.T @ r_p / np.where(ok, norm2, 1.0), 0.0) * scale
        gain = np.where(ok, value**2 * norm2 / scale**2, -np.inf)
        gain[value < lower] = -np.inf  # an effect of unphysical sign cannot be the answer
        gain[sel.chosen] = -np.inf
        short = per_kind(gain, kinds, shortlist)
        rx = Reanalysis(res, st)  # made once for the screen of saturating kinds and the trials' quick fits
        stiff = saturated(rx, [candidates[i] for i in sel.chosen], sel.values, candidates, gain, shortlist)
        order = np.union1d(short, np.array(list(stiff), dtype=np.int64))
        order = np.setdiff1d(np.union1d(np.union1d(order, _companions(candidates, sel.chosen)),
                                        _whole(candidates, short)), sel.chosen)
        if not order.size:
            break
        start = {j: v for j, v in stiff.items() if j not in short}
        adds = [(int(j),) for j in order] + halves.shortlist(A_p, r_p, scale, lower, sel.chosen, shortlist)
        step = (res, candidates, sel, fit, held, A, scale, value, P, rx, newton_steps, bounds, pen, p0.size, runner,
                moves, alpha)
        new, idx = _weighed(step, adds, start)
        if new is None and not resonant_tried and not sel.within_noise(n - p0.size, alpha):
            resonant_tried = True
            screened = resonant(rx, [candidates[i] for i in sel.chosen], sel.values, candidates, halves.pairs,
                               halves.gains(A_p, r_p, scale, lower, sel.chosen), shortlist)
            new, idx = _weighed(step, [pair for pair, _ in screened],
                                {j: v for pair, vs in screened for j, v in zip(pair, vs)}, resonant=True)
        if new is None:
            break
        idx, fit = _prune(res, candidates, idx, new, newton_steps, bounds, pen, p0.size, runner)
        adopt(sel, idx, fit, pen)
    return sel


def _weighed(step, adds: list, start: dict, resonant: bool = False) -> tuple:
    """(estimate, effects) of the first of the additions ``adds`` (tuples of candidate indices), ranked by
    the criterion of their trial fits (:class:`.scan.Ranking`, from the magnitudes ``start`` gives or else
    their linear estimates; a pair pays for its second effect), that is kept (:func:`_kept`, an addition
    of a ``coarse`` kind first walked: :func:`_walked`); (None, None) where none is. A screened support
    or body refused gives way to the next best; a candidate of the linear shortlist refused ends the
    step. ``step``: the search's state at this step (:func:`search`); ``resonant``: the additions are the
    bodies of :func:`.scan.resonant` (:func:`_kept`)."""
    res, candidates, sel, fit, held, A, scale, value, P, rx, newton_steps, bounds, pen, n_params, runner, moves, \
        alpha = step
    trials = [([candidates[i] for i in sel.chosen + list(add)],
               np.r_[sel.values, [start.get(j, max(value[j], 0.0)) for j in add]]) for add in adds]
    ranking = Ranking(res, fit.state, trials, fit.p, bounds, P, runner, rx, [len(add) * pen for add in adds])
    fits = ranking.fits
    for best in iter(ranking.next, None):
        add = list(adds[best])
        idx = sel.chosen + add
        new = _kept(res, candidates, sel, fit, idx, fits[best], held, A[:, add], scale[idx], newton_steps,
                    bounds, pen, n_params, len(add), (rx, P), resonant)
        if new is None and moves is not None and len(add) == 1 and \
                worth(sel.chi2[-1], fits[best].chi2, res.n_rows, n_params + len(idx), pen):
            new, idx = _walked(res, candidates, sel, fit, add[0], fits[best], held, moves, newton_steps, bounds,
                               pen, n_params, runner, alpha)
        if new is not None:
            return new, idx
        if len(add) == 1 and add[0] not in start:
            break
    return None, None


def _walked(res, candidates, sel, fit, j, trial, held, moves, newton_steps, bounds, pen, n_params, runner,
            alpha) -> tuple:
    """(estimate, effects) of the chosen effects and candidate ``j`` walked (``moves``, the others held)
    to where it fits best, where it is then kept (:func:`_kept`); else (None, None). An addition worth
    its penalty that does not predict the held-out folds may be a real effect the candidates' grid
    misplaces (dev seed 12: a region 19 x 28 mm met by a 22 x 20 mm patch 10 mm off, which made four
    of ten modes' predictions worse; walked onto the region, eight of ten better). Only the kinds whose
    candidates lie on a grid coarser than the mesh (``coarse``, :mod:`.catalogue`): stiffeners lie on
    every row of nodes, masses on every node, and a walk gives a model error there one more chance to
    pass (ho_noise_card, the hold-out's card without any effect: a stiffener refused at its row was
    walked across a corner and kept)."""
    if not getattr(kind(candidates[j].kind), "coarse", False) or not moves(j):
        return None, None
    stay, idx = set(sel.chosen), sel.chosen + [j]
    start = estimate(res, fit.p, [candidates[i] for i in idx], trial.values, newton_steps, bounds)
    if start.state is None:
        return None, None
    walked = refine(res, candidates, adopt(Selection(), idx, start, pen),
                    lambda i: [] if i in stay else moves(i), bounds, newton_steps, alpha=alpha, runner=runner)
    if walked.chosen[:-1] != sel.chosen or walked.chosen[-1] == j:
        return None, None
    idx = walked.chosen
    k = candidates[idx[-1]]
    column = res.effect_columns(fit.state, [k]) * k.spec.scale
    scale = np.array([candidates[i].spec.scale for i in idx])
    new = _kept(res, candidates, sel, fit, idx, walked, held, column, scale, newton_steps, bounds, pen, n_params)
    return (new, idx) if new is not None else (None, None)


def _kept(res, candidates, sel, fit, idx, trial, held, column, scale, newton_steps, bounds, pen, n_params,
          n_added: int = 1, refit=None, resonant: bool = False):
    """The estimate of effects ``idx`` (the chosen ones and an addition of its last ``n_added``, whose
    trial fit is ``trial`` and columns at the state without it ``column``) when the addition is kept: its
    chi^2 drop is worth ``n_added`` penalties ``pen`` (:func:`worth`) and it predicts the held-out folds
    to first order (:func:`.held_out.predicts`) from the state without it or along the secant to the
    state with it (:func:`.held_out.secant`); else None. Either first-order model can fail a real effect
    where the modes respond nonlinearly (a share of a mass beside another: the secant; a bar across the
    card: the state without it); a model error taken for an effect fails both. ``refit``: (reanalysis, the
    parameters' columns there) with which a body (:func:`.halves.together`) that both first-order models fail
    is weighed by its folds' refits (:func:`.held_out.refit_predicts`), each half also beside the other unless
    it is ``resonant`` (a body of :func:`.scan.resonant`: a bracket's halves move the modes in opposite senses,
    neither alone predicts anything). Single additions are not: so weighed, a spring rode along a box's hidden
    mass and a line mass of the hold-out's card."""
    effects = [candidates[i] for i in idx]
    new = estimate(res, fit.p, effects, trial.values, newton_steps, bounds)
    if not worth(sel.chi2[-1], new.chi2, res.n_rows, n_params + len(idx), n_added * pen):
        return None
    r = fit.state.r
    if predicts(res, r, held, column) or predicts(res, r, *secant(res, held, column, new, effects, scale)):
        return new
    body = n_added == 2 and together(effects[-2], effects[-1])
    if refit is not None and body and refit_predicts(res, *refit, fit, new, effects, n_added, bounds, newton_steps,
                                                     halves=not resonant):
        return new
    return None


def without_vanished(res, candidates, sel: Selection, bounds=None, newton_steps: int = 8,
                     alpha: float = ALPHA) -> Selection:
    """``sel`` without the effects that later steps left within one standard deviation of zero
    (a companion that the refined others made needless), the rest re-estimated. Not the kinds that
    saturate: a spring that pins the plate has a standard deviation far above its stiffness (any stiffer
    one fits about as well) and is far from none (dev seed 5's rigid standoff, dropped here once the
    covariance no longer read its column as no rank); :func:`noticed` weighs their removal."""
    keep = [k for k, (i, v, s) in enumerate(zip(sel.chosen, sel.values, sel.sigma))
            if abs(v) > s or getattr(kind(candidates[i].kind), "saturates", False)]
    if len(keep) == len(sel.chosen):
        return sel
    idx = [sel.chosen[k] for k in keep]
    fit = estimate(res, sel.p, [candidates[i] for i in idx], np.asarray(sel.values)[keep], newton_steps, bounds)
    return adopt(sel, idx, fit, penalty(res.n_rows, len(candidates), alpha))


#: Gauss-Newton steps of each fit that leaves an effect out (:func:`noticed`)
NOTICE_STEPS = 4


def noticed(res, candidates, sel: Selection, bounds=None, newton_steps: int = NOTICE_STEPS,
            alpha: float = ALPHA) -> Selection:
    """``sel`` without the effects whose removal the data do not notice (issue 37: nothing is reported
    that the data do not need): each effect is left out in turn, the others and the declared parameters
    refitted; while the least missed one raises chi^2 by less than one effect's penalty
    (:func:`worth`), it is dropped. Run last, after the steps that move the model under the effects
    (the mesh correction measured with them, the plate theory's share)."""
    pen = penalty(res.n_rows, len(candidates), alpha)
    idx = list(sel.chosen)
    while idx:
        trials = [([i for i in idx if i != j], estimate(res, sel.p, [candidates[i] for i in idx if i != j],
                                                         np.delete(sel.values, k), newton_steps, bounds))
                  for k, j in enumerate(idx)]
        keep, fit = min(trials, key=lambda t: t[1].chi2)
        if fit.state is None or worth(fit.chi2, sel.chi2[-1], res.n_rows, np.size(sel.p) + len(idx), pen):
            break
        sel, idx = adopt(sel, keep, fit, pen), keep
    return sel


def refine(res, candidates, sel: Selection, neighbours, bounds=None, newton_steps: int = 8,
           alpha: float = ALPHA, runner: Runner | None = None) -> Selection:
    """Local search on the geometry of the effects found: each chosen candidate is swapped in turn
    for each of ``neighbours(i)`` (candidate indices of the same kind next to it, e.g. a segment
    one piece longer or shorter), all magnitudes and the declared parameters re-estimated; the
    best swap is kept while it lowers chi^2, then effects the others now explain are pruned.
    Forward selection adds effects greedily on a coarse set of places; this lets a place found
    early move to where the effects found later leave it best; the two halves of a body move
    together (:func:`.halves.body_moves`). The swaps are ranked by
    :class:`.scan.Ranking` (``runner``: where their full fits run)."""
    pen = penalty(res.n_rows, len(candidates), alpha)
    n_par = np.size(sel.p)
    idx = list(sel.chosen)
    fit = Fit(sel.p, sel.values, sel.state, np.zeros((0, 0)))
    improved = bool(idx)
    while improved:
        improved = False
        P = res.param_columns(fit.state)  # held while ranking the swaps, as in :func:`search`
        found = bodies(candidates, idx) if hasattr(neighbours, "half") else []
        halves = {k for pair in found for k in pair}
        swaps = [idx[:k] + [j] + idx[k + 1:] for k, i in enumerate(idx) if k not in halves
                 for j in neighbours(i) if j not in idx]
        swaps = [list(sw) for sw in dict.fromkeys(map(tuple, swaps + body_moves(candidates, idx, found, neighbours)))]
        ranking = Ranking(res, fit.state, [([candidates[t] for t in sw], moved_values(candidates, idx, sw, fit.values))
                                           for sw in swaps], fit.p, bounds, P, runner, beat=fit.chi2 * (1 - 1e-6))
        k = ranking.next()
        if k is not None:
            trial = ranking.fits[k]
            new = estimate(res, trial.p, [candidates[t] for t in swaps[k]], trial.values, newton_steps, bounds)
            if new.chi2 < fit.chi2 * (1 - 1e-6):
                idx, fit, improved = swaps[k], new, True
    if idx == list(sel.chosen):
        return sel
    return adopt(sel, *_prune(res, candidates, idx, fit, newton_steps, bounds, pen, n_par, runner), pen)


def moved_values(candidates, idx, swap, values) -> np.ndarray:
    """The magnitudes a swap of the effects ``idx`` for ``swap`` starts from: ``values``, each effect
    that moved at its kind's (:func:`.catalogue.moved_value`)."""
    return np.array([v if i == j else moved_value(candidates[i], candidates[j], v)
                     for i, j, v in zip(idx, swap, values)], float)


def orth(A):
    """An orthonormal basis of the span of ``A``'s columns (directions weaker than 1e-10 of the
    strongest dropped)."""
    if A.shape[1] == 0:
        return np.zeros((A.shape[0], 0))
    U, s, _ = np.linalg.svd(A, full_matrices=False)
    return U[:, s > 1e-10 * s[0]] if s.size and s[0] > 0 else np.zeros((A.shape[0], 0))


def _companions(candidates, chosen) -> np.ndarray:
    """Candidates on the very nodes of a chosen one (the rotary inertia of a mass found, a spring
    under it): always tried next, whatever their linear score, since a part found is the likeliest
    place of its other properties."""
    taken = {tuple(candidates[i].nodes.tolist()) for i in chosen}
    return np.array([j for j, c in enumerate(candidates) if j not in chosen and tuple(c.nodes.tolist()) in taken
                     and c.nodes.size == 1], dtype=np.int64)


def _whole(candidates, idx) -> np.ndarray:
    """For each of ``idx`` whose kind has pieces of a larger whole (its optional ``whole``: a stiffener on
    part of a line), that whole: always tried beside it, since a piece can score best on its own where
    the effect spans the whole."""
    return np.unique(np.array([candidates[i].spec.whole(candidates, i) for i in idx
                               if hasattr(candidates[i].spec, "whole")], dtype=np.int64))


def _prune(res, candidates, idx, fit, steps, bounds, pen, n_params, runner: Runner | None = None):
    """Backward check after each addition: drop an earlier effect whenever the others, re-estimated
    without it, reach a lower criterion (greedy choices made before the right effect was in); the
    drops a quick fit shows to be far worse are not re-estimated (:func:`.scan.worth_full`, its
    quick fits run where ``runner`` says)."""
    while len(idx) > 1:
        best = None
        keeps = [[i for t, i in enumerate(idx) if t != drop] for drop in range(len(idx) - 1)]
        trials = [([candidates[i] for i in keep], np.delete(fit.values, drop)) for drop, keep in enumerate(keeps)]
        for drop, (keep, full) in enumerate(zip(keeps, worth_full(res, fit.state, trials, fit.p, bounds,
                                                                   fit.chi2 + pen, steps, runner))):
            if not full:
                continue
            trial = estimate(res, fit.p, trials[drop][0], trials[drop][1], steps, bounds)
            if trial.chi2 + len(keep) * pen < fit.chi2 + len(idx) * pen and (best is None or trial.chi2 < best[1].chi2):
                best = (keep, trial)
        if best is None:
            break
        idx, fit = best
    return idx, fit


def forward_select(model, candidates, f_test, sigma: float, max_effects: int = 3, newton_steps: int = 8,
                   shortlist: int = 3, alpha: float = ALPHA) -> Selection:
    """:func:`search` on frequencies alone: ``f_test`` [Hz] paired in order with the first
    len(f_test) elastic modes of ``model``, relative noise ``sigma`` (e.g. 0.002), no declared
    parameters."""
    from ..testdata import MeasuredModes
    from .residual import ModalResidual, Observation

    f_test = np.asarray(f_test, dtype=float)
    if not sigma > 0:
        raise ValueError(f"sigma (relative frequency noise) must be > 0, got {sigma}")
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(f_test.size, float(sigma)))],
                        lambda p: [model])
    return search(res, candidates, max_effects=max_effects, newton_steps=newton_steps, shortlist=shortlist,
                  alpha=alpha)
