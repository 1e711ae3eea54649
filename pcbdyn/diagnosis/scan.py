"""Ranking trial fits: which of several sets of effects fits the data best, at the least cost.

Forward selection (:func:`.select.search`) ranks a shortlist of candidates, each fitted with the
effects already chosen and the declared parameters for a few Gauss-Newton steps; the local search
(:func:`.select.refine`) ranks the moves of each effect found. Every trial starts from one solved
state, so each is first fitted on that state's reanalysis (:mod:`.reanalysis`: no sparse solve),
and of the :data:`FULL_RANK` best of them only those whose quick fit could still be the best
(:class:`Ranking`) are fitted again with full re-solves, which decide; so is every trial a reanalysis
cannot follow (adding or removing a rib changes the modes beyond a first-order basis: kinds with
``reanalysed = False``), which is never fitted on it. Both kinds of fits are independent jobs: they
run in local worker processes (the quick ones always there) or on a Dask cluster
(:func:`pcbdyn.parallel.run_jobs`) when a :class:`Runner` says so, with the same results as in
this process."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..parallel import run_jobs
from .catalogue import kind
from .fitting import RANK_STEPS, Fit, estimate
from .reanalysis import Reanalysis

#: a scan tells its progress at most this often [s] (and when it ends): quick fits take 40 ms
PROGRESS_EVERY = 0.5
#: the quick fits' best this many are fitted again with full re-solves
FULL_RANK = 3
#: of a kind whose effect saturates (``saturates = True``), this many candidates best by their linear
#: score are evaluated at :data:`SATURATED_VALUES` on the reanalysis (:func:`saturated`)
SATURATED_SCREEN = 40
#: the magnitudes of that screen, in multiples of the kind's ``scale``
SATURATED_VALUES = (10.0, 100.0)
#: of the bodies one of whose halves saturates (a mass on a spring: a bracket), this many pairs best by their
#: linear score are evaluated at :data:`RESONANT_VALUES` on the reanalysis where a step finds nothing
#: (:func:`resonant`; dev seed 23's bracket: the pair nearest it ranked 114th of 804 by the linear score)
RESONANT_SCREEN = 300
#: the magnitudes of that screen, in multiples of each half's ``scale`` (every combination of the two)
RESONANT_VALUES = (0.3, 1.0, 3.0)
#: a quick fit's chi^2 is trusted to this share of the solved state's (a reanalysis is first order
#: in the parameters; 120 quick fits against their full fits on dev seeds 3, 12 and 20: 95 % within
#: 2.1 %, the worst 5.7 %, which changed no local search's choice)
SCREEN_MARGIN = 0.05


@dataclass
class Runner:
    """Where trial fits run: ``workers`` local processes (1: this process; None: the cores) or
    the Dask cluster at ``scheduler``; ``progress(msg)`` is told how many of a scan are done
    (:data:`PROGRESS_EVERY`)."""

    workers: int | None = 1
    scheduler: object = None
    progress: object = None

    def map(self, fn, jobs: list, shared, what: str = "fits") -> list:
        """``fn(*job, shared)`` for every job, results in the jobs' order."""
        if not jobs:
            return []
        count, told = [0], [time.monotonic()]

        def done(_):
            count[0] += 1
            now = time.monotonic()
            if self.progress is not None and (count[0] == len(jobs) or now - told[0] >= PROGRESS_EVERY):
                told[0] = now
                self.progress(f"{count[0]} of {len(jobs)} {what}")

        out = sorted(run_jobs(fn, [(k, *job) for k, job in enumerate(jobs)], shared, self.workers, self.scheduler, done),
                     key=lambda item: item[0][0])
        return [result for _, result in out]


def reach(state) -> float:
    """How far a quick fit on the reanalysis of the solved ``state`` may lie from its full fit, in chi^2
    (:data:`SCREEN_MARGIN` of the state's): the one margin of every screen that decides what is re-solved."""
    return SCREEN_MARGIN * state.chi2


def _full_fit(k, cands, v0, p, shared):
    """One full trial fit (a job): (chi^2, magnitudes, parameters)."""
    res, bounds, P = shared
    fit = estimate(res, p, cands, v0, RANK_STEPS, bounds, param_columns=P)
    return fit.chi2, fit.values, fit.p


def _followed(state, cands) -> bool:
    """True when a reanalysis of ``state`` can follow the trial ``cands``: every effect it adds or
    drops is of a kind a first-order basis follows."""
    here, there = {c.name for c in state.candidates}, {c.name for c in cands}
    changed = [c for c in list(cands) + list(state.candidates) if (c.name in here) != (c.name in there)]
    return all(getattr(kind(c.kind), "reanalysed", True) for c in changed)


def worth_full(res, state, trials: list, p, bounds, limit: float, steps: int = RANK_STEPS,
               runner: Runner | None = None) -> list:
    """For each of ``trials`` = [(candidates, initial magnitudes)] from the solved ``state``: False
    where its quick fit on the state's reanalysis leaves chi^2 above ``limit`` by more than the
    reanalysis can be off (:data:`SCREEN_MARGIN` of the state's chi^2), so that no full fit could
    reach it; True otherwise (and for the trials a reanalysis cannot follow). ``steps``: Gauss-Newton
    steps of the quick fits (as many as the full fits they stand for, so that only the reanalysis
    differs); ``runner``: where they run."""
    idx = [k for k, (cands, _) in enumerate(trials) if _followed(state, cands)]
    chi2 = _screen(res, state, [trials[k] for k in idx], p, bounds, res.param_columns(state) if idx else None, steps,
                   runner)
    out = [True] * len(trials)
    for k, c in zip(idx, chi2):
        out[k] = bool(c <= limit + reach(state))
    return out


def _screen(res, state, trials: list, p, bounds, P, steps: int, runner: Runner | None = None, reduced=None) -> list:
    """chi^2 of each of ``trials`` fitted on the reanalysis of ``state`` (``reduced``, made here where not
    given; ``P``: the declared parameters' columns, held: a reanalysed state has no full modes). The quick fits are
    independent jobs too, run in ``runner``'s local processes even where it names a cluster: each
    takes ~40 ms, and what they share is the whole solved state."""
    if not trials:
        return []
    local = Runner() if runner is None else Runner(runner.workers, None, runner.progress)
    rx = reduced or Reanalysis(res, state)
    rx.prepare([c for cands, _ in trials for c in cands])
    shared = (res, rx, p, bounds, P, steps)
    return local.map(_quick_fit, trials, shared, "trials screened on the reanalysis")


def _quick_fit(k, cands, v0, shared):
    """One trial fit on the reanalysis (a job): its chi^2."""
    res, rx, p, bounds, P, steps = shared
    return estimate(res, p, cands, v0, steps, bounds, param_columns=P, reduced=rx).chi2


def saturated(rx, effects, values, candidates, gain, per_kind: int) -> dict:
    """{candidate index: magnitude} of the ``per_kind`` candidates of each kind whose effect saturates
    (a support stiffens the modes near it up to a pin) that leave the least chi^2 on the reanalysis
    ``rx`` of a state (its parameters, ``effects`` at ``values``), each at the best of
    :data:`SATURATED_VALUES` (or the kind's ``saturated_values``), among the :data:`SATURATED_SCREEN` (or
    its ``saturated_screen``) best by their linear score ``gain``. A kind whose quick fits the
    reanalysis does not follow (a rib) is still ranked on it: the screen only chooses what is fitted.
    Near its saturation every place of such an effect has about the same linear score (a stiff
    spring at the edge of a large thin card: the true place's was 106th of 1730), while its
    saturated effect differs from place to place."""
    kinds = np.array([c.kind for c in candidates])
    todo = [k for k in np.unique(kinds) if getattr(kind(k), "saturates", False)]
    out = {}
    for k in todo:
        spec = kind(k)
        idx = np.flatnonzero((kinds == k) & np.isfinite(gain))
        idx = idx[np.argsort(-gain[idx], kind="stable")[:getattr(spec, "saturated_screen", SATURATED_SCREEN)]]
        grid = spec.scale * np.asarray(getattr(spec, "saturated_values", SATURATED_VALUES), float)[:, None]
        out.update({add[0]: v[0] for add, v in _on_grid(rx, effects, values, candidates, [(int(j),) for j in idx],
                                                        [grid] * idx.size, per_kind)})
    return out


def resonant(rx, effects, values, candidates, pairs, gain, per_group: int) -> list:
    """[(pair, its two magnitudes)]: the ``per_group`` ``pairs`` (n, 2) of candidate indices, halves of one
    body of which one saturates, that leave the least chi^2 on the reanalysis ``rx`` of a state (its
    parameters, ``effects`` at ``values``), each at the best combination of :data:`RESONANT_VALUES`, among
    the :data:`RESONANT_SCREEN` best by their linear score ``gain``. A mass on a spring has a mode of its
    own: where that mode falls among the structure's sets its effect on them, which no first-order score
    follows (dev seed 23: an 11 g bracket on 35 kN/m at 280 Hz; near it the pairs' linear scores ranked
    them 114th and worse, the screen first, 3.6 mm from it)."""
    sat = np.array([any(getattr(candidates[j].spec, "saturates", False) for j in pair) for pair in pairs], bool)
    idx = np.flatnonzero(sat & np.isfinite(gain))
    idx = idx[np.argsort(-gain[idx], kind="stable")[:RESONANT_SCREEN]]
    combos = np.array([(a, b) for a in RESONANT_VALUES for b in RESONANT_VALUES], float)
    adds = [tuple(int(k) for k in pairs[m]) for m in idx]
    grids = [combos * [candidates[i].spec.scale, candidates[j].spec.scale] for i, j in adds]
    return _on_grid(rx, effects, values, candidates, adds, grids, per_group)


def _on_grid(rx, effects, values, candidates, adds: list, grids: list, keep: int) -> list:
    """[(addition, its magnitudes)]: the ``keep`` additions ``adds`` (tuples of candidate indices) that
    leave the least chi^2 on the reanalysis ``rx`` of a state (its parameters, ``effects`` at
    ``values``), each at the best row of its grid of magnitudes (``grids``: one (n, len(addition))
    array per addition): the screens of :func:`saturated` and :func:`resonant`."""
    best = []
    rx.prepare([candidates[j] for add in adds for j in add])
    for add, grid in zip(adds, grids):
        cands = list(effects) + [candidates[j] for j in add]
        best.append((*min((_reduced_chi2(rx, rx.st.p, cands, np.r_[values, v]), tuple(v)) for v in grid), add))
    return [(add, np.array(v)) for _, v, add in sorted(best)[:keep]]


def _reduced_chi2(rx, p, cands, values) -> float:
    try:
        return rx.evaluate(p, cands, values).chi2
    except (ValueError, ArithmeticError, np.linalg.LinAlgError):
        return np.inf


class Ranking:
    """Trials = [(candidates, initial magnitudes)] from the solved ``state`` ranked by their criterion, chi^2
    plus ``cost`` (the penalties of what each adds; declared parameters from ``p``, their columns ``P`` held;
    ``reduced``: the state's reanalysis where already made); ``beat``: where only a trial whose chi^2 is below
    it matters (a local search). Every trial is first fitted on the reanalysis; full fits (re-solves, which
    decide) are made only as far as the order needs them: a trial whose quick criterion, off by up to
    :data:`SCREEN_MARGIN` of the state's chi^2, cannot come below the best full one is never re-solved. Of
    the trials a reanalysis follows only the :data:`FULL_RANK` best by their quick criteria may be (by chi^2 alone,
    pairs crowded out the single addition that won: dev seed 20, whose pick then hung on round-off); where no more
    than that compete outside a local search, all are re-solved unscreened (a few brackets of the resonant
    screen: a mass on a spring near its own mode is where a first-order basis is worst). The others (a rib added or
    removed) are always re-solved and never fitted on the reanalysis, as :func:`worth_full` never screens them:
    such quick fits were within 1.7 % of the state's chi^2 on dev seeds 2 and 19, but 36 % above the full fit of the
    rib move that won on the bench's ``stiffener_col_wedge``."""

    def __init__(self, res, state, trials: list, p, bounds, P, runner: Runner | None = None, reduced=None,
                 cost=None, beat: float = np.inf):
        self.trials, self.p, self.bounds, self.P, self.beat = trials, p, bounds, P, beat
        self.runner, self.res = runner or Runner(), res
        self.cost = np.zeros(len(trials)) if cost is None else np.asarray(cost, float)
        self.reach = reach(state)
        followed = np.array([_followed(state, cands) for cands, _ in trials], bool)
        k_f = np.flatnonzero(followed)
        few = k_f.size <= FULL_RANK and not np.isfinite(beat)  # then all are re-solved unscreened
        screened = k_f[:0] if few else k_f
        quick = np.full(len(trials), np.nan)
        quick[screened] = _screen(res, state, [trials[k] for k in screened], p, bounds, P, RANK_STEPS, runner,
                                  reduced)
        self.quick = np.where(np.isfinite(quick), quick + self.cost, -np.inf)  # none or failed: decides nothing
        eligible = np.r_[k_f[np.argsort(quick[k_f] + self.cost[k_f], kind="stable")[:FULL_RANK]],
                         np.flatnonzero(~followed)]
        self.pending = {int(k) for k in eligible}
        self.fits: list = [None] * len(trials)
        self.tried: set = set()

    def criterion(self, k: int) -> float:
        """Re-solved trial k's chi^2 and cost."""
        return self.fits[k].chi2 + self.cost[k]

    def next(self):
        """The index of the untried trial of least criterion once no trial not yet re-solved could beat it,
        marked tried; None where none comes below ``beat``."""
        while True:
            done = [k for k, f in enumerate(self.fits) if f is not None and k not in self.tried]
            best = min(done, key=self.criterion, default=None)
            # the best full fit lies below that of every trial re-solved and, up to the margin, every quick one
            bound = min([self.beat] + [self.criterion(k) for k in done]
                        + [self.quick[k] + self.reach for k in self.pending if self.quick[k] > -np.inf])
            need = (sorted(k for k in self.pending if self.quick[k] == -np.inf)
                    or sorted(k for k in self.pending if self.quick[k] - self.reach < bound))
            if not need:
                break
            self.pending -= set(need)
            done_fits = self.runner.map(_full_fit, [(self.trials[k][0], self.trials[k][1], self.p) for k in need],
                                        (self.res, self.bounds, self.P), "trial fits")
            for k, (chi2, values, fp) in zip(need, done_fits):
                self.fits[k] = Fit(fp, values, None, np.zeros((0, 0)), chi2_value=chi2)
        if best is None or not self.criterion(best) < self.beat:
            return None
        self.tried.add(best)
        return best
