"""Where a rib lies and what section it has, fitted on meshes that follow it (issue 37: a bar need
not span the board, nor run along x or y, and it carries its mass).

The search places a stiffener on one of the lines it tries (across the whole plate in a few
directions, :mod:`.stiffener`), embedded in the cells it crosses. A glued bar stops short of the
edges, runs at its own angle and has its own section; and embedded in coarse cells a rib is stiffer
than on a row of nodes (the cells' rotations are interpolated under it: on an 8 mm mesh a diagonal
bar raised the first frequencies by 3 %, chi^2 300000 at the bar's place against 5000 meshed along
it). So each rib is moved in six ways on meshes along it (:func:`.conforming.remeshed`): across
itself, turned about its middle, each end along its line (extended or trimmed), slid along its line
(both ends), and its section height (its mass per length is 12 rho EI / (E h^2),
:meth:`.stiffener._Stiffener.mass`). Each move is a line search: the declared parameters and all
magnitudes fitted by the one fitting engine (:func:`.fitting.estimate`, thesis ch. 4) at two places
either side, and the rib taken to the vertex of the parabola through the three chi^2 (:func:`vertex`);
its step grows while the vertex lies beyond the outer places and shrinks once it lies between them; a
move is taken only where chi^2 falls by more than the data resolve (:func:`resolved`), and a round
ends the fit where it takes no move, or where it gains less than the mesh's own noise while no move
it took reached its outer place
(:func:`settled`).
Each place is a mesh of its own, so chi^2 carries the mesh's changes as noise (a few % of it on a card
with parts: 906 at the bar's line, 950 and 960 a quarter of a millimetre to either side); a parabola
through places an element apart reads through it where finite differences at a fraction of an element
would not. The line searches polish; the long way from the search's full-span line to a bar that stops
short of the edges at its own angle is covered first by the bounded Gauss-Newton (thesis ch. 4) on the
ends and ln h with the declared parameters and magnitudes, the geometry's columns by forward
differences (:data:`STEP` half an element along the ends, :data:`HEIGHT_STEP` in ln h), each a re-mesh
run as a job. Far from the bar
those columns can point its step uphill, however halved: it then tries Marquardt's damped steps
(:data:`pcbdyn.updating.gauss_newton.DAMPING`; a steel bar 25 mm short of where the search put it:
chi^2 2.5e5 where it stopped without them, 1.6e4 with); where the mesh's noise still defeats it,
the line searches start from the search's line.
Where the line searches settle, a rib too long or slid along itself may still need its ends and its
section changed together, which no single move does, and a magnitude's fit can stop where the modes'
pairing changes. So where the noise does not explain the fit (:func:`explained`), a screen of
restarts (:func:`restarts`: pieces and slides of the rib, at three heights, from two EI) is fitted,
and the line searches go on from the best where it gains more than the data resolve
(:func:`_restarted`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..domain import StructureError
from ..problems.error_budget import noise_explains, variance_left
from ..updating.gauss_newton import DAMPING, gauss_newton, taken
from . import conforming
from .catalogue import kind
from .fitting import UPPER, Fit, estimate
from .layout import from_structure
from .selection import ALPHA
from .stiffener import extent, in_its_plane, in_plane, normal

#: a rib's coordinates: its ends in its plate's plane and ln h (a slide moves both ends)
COORDINATES = 5
#: the moves of a rib and their first steps ([element sizes]; the height's in ln h)
MOVES = {"across": 0.25, "turn": 0.25, "end0": 0.5, "end1": 0.5, "slide": 0.5, "height": 0.25}
#: a move's step grows and shrinks within these multiples of its first step
STEP_RANGE = (0.25, 8.0)
#: rounds over all moves, at most (:func:`settled` ends the search sooner): dev seed 15's steel bar on a
#: 0.91 mm board still lost half its chi^2 per round after two (18785 there; rounds more from that place
#: took it to 1013, both ends within 1 mm of the bar's)
ROUNDS = 12
#: a round that lowers chi^2 by less than this share of it, creeping inside its steps, ends the search:
#: re-meshing a rib a quarter of an element aside changes chi^2 by a few % (module doc)
ROUND_GAIN = 0.01
#: [element sizes] the forward-difference step of an end coordinate: half an element, so that the mesh's
#: own noise (a few % of chi^2 between re-meshes, module doc) is a small part of the difference (an eighth
#: of an element: the fit ended wherever its start sent it; housing dev h3-h7, found 1/9 against 4/9 now)
STEP = 0.5
#: the forward-difference step of ln h: the height's change re-meshes nothing, and 0.5 in ln h would be a
#: factor 4.5 in EI, far from a first-order difference
HEIGHT_STEP = 0.125
#: Gauss-Newton steps (each 1 + 5 re-meshed solves per rib, and halvings)
GN_STEPS = 12
#: Gauss-Newton steps of each trial fit (from the values at the present place)
TRIAL_STEPS = 3
#: [m] bounds of the section height (a foil to a deep frame member)
HEIGHT = (0.5e-3, 30e-3)
#: [element sizes] the shortest rib (shorter, an end pair collapses into a point effect)
MIN_LENGTH = 2.0
#: the places each rib restarts from where its line searches settle, as (start, end) along it in shares
#: of its length: a quarter trimmed at either end, slid an eighth either way, and its middle half. The
#: line searches move one coordinate at a time, and a rib too long or slid along itself must change its
#: section with its ends (housing dev seed 3: a bar found 40 % too long, 0.1 of its EI, chi^2 37073; its
#: first three quarters at 1.6 times its height 22934, at its height 94461; seed 5: slid an eighth, at
#: 0.75 times its height, 3247 against 7106; seed 7: a bar half as long as the search's edge-to-edge line,
#: 0.02 of its EI there, chi^2 19673; its middle half at 1.6 times its height 11380, walked to 5400, the
#: true bar's start 4296)
RESTARTS = ((0.0, 0.75), (0.25, 1.0), (-0.125, 0.875), (0.125, 1.125), (0.25, 0.75))
#: each restart is tried at the rib's height and at it times and over this factor
HEIGHT_LADDER = 1.6
#: and from its EI (scaled as its length) times each of these: a magnitude's fit can stop on the way up
#: where the modes' pairing changes (a steel bar's EI fitted from 0.13 of it stops there, from 0.4 of it
#: reaches it)
EI_STARTS = (1.0, 3.0)
#: restarts screened at most (each a screen of :data:`RESTARTS`, heights and :data:`EI_STARTS` per rib,
#: then line searches)
SCREENS = 2


@dataclass
class Ribs:
    """What the fit ends on: the structure's ``models`` meshed along the ribs, the residual ``res``
    there, the effects ``placed`` on it (ribs at their fitted ends and sections), and the ``fit`` of
    (declared parameters, magnitudes)."""

    models: object
    res: object
    placed: list
    fit: Fit


def moved(rib, move: str, amount: float, h: float):
    """``rib`` moved by ``amount`` ([m]; ln h for the height) in one of :data:`MOVES` (None where it
    would end shorter than :data:`MIN_LENGTH` elements or its height leave :data:`HEIGHT`)."""
    path = in_plane(rib)
    d = (path[1] - path[0]) / np.linalg.norm(path[1] - path[0])
    n = normal(path)
    height = rib.data.get("height", kind("stiffener").section.h)
    if move == "across":
        path = path + amount * n
    elif move == "turn":
        path = path + np.array([-amount, amount])[:, None] * n
    elif move == "end0":
        path[0] -= amount * d
    elif move == "end1":
        path[1] += amount * d
    elif move == "slide":
        path = path + amount * d
    else:
        height = height * np.exp(amount)
    return _on(rib, path, height, h)


def _on(rib, path, height: float, h: float):
    """``rib`` on ``path`` (2, 2) [m] in its plate's plane with section ``height`` [m]; None where it
    would be shorter than :data:`MIN_LENGTH` elements or its height outside :data:`HEIGHT`."""
    if not HEIGHT[0] <= height <= HEIGHT[1] or np.linalg.norm(path[1] - path[0]) < MIN_LENGTH * h:
        return None
    return kind("stiffener").along(replace(rib, data={**rib.data, "height": float(height)}), path)


def _through(offsets, chi2):
    """(step, slope, curvature) of the parabola through three (offset, chi^2) points equally spaced, in
    steps from the middle one; None where it opens down."""
    (a, _, c), d = chi2, offsets[2] - offsets[1]
    curve = a - 2.0 * chi2[1] + c
    return (d, 0.5 * (c - a), curve) if curve > 0.0 and np.isfinite(curve) else None


def vertex(offsets, chi2) -> float:
    """The offset of the least chi^2 on the parabola through three (offset, chi^2) points equally
    spaced (the best of them where the parabola opens down), kept between the outer two."""
    fit = _through(offsets, chi2)
    if fit is None:
        return float(offsets[int(np.argmin(chi2))])
    d, slope, curve = fit
    return float(np.clip(offsets[1] - d * slope / curve, offsets[0], offsets[2]))


def parabola(offsets, chi2, x: float) -> float:
    """The chi^2 at offset ``x`` on the parabola through three (offset, chi^2) points equally spaced
    (the least of them where it opens down: :func:`vertex` then takes that point)."""
    fit = _through(offsets, chi2)
    if fit is None:
        return float(min(chi2))
    d, slope, curve = fit
    t = (x - offsets[1]) / d
    return float(chi2[1] + slope * t + 0.5 * curve * t * t)


def resolved(fit, n_rows: int, n_ribs: int) -> float:
    """The least fall of chi^2 that a move of a rib must make to be taken: one unit of chi^2 (the edge
    of a parameter's 1-sigma interval), in units of the variance the fit leaves where that exceeds the
    stated noise (as :func:`.selection.worth` weighs an effect). A move that gains less lies within the
    geometry's own uncertainty: the data cannot tell the two places apart, and each move costs re-meshed
    solves (dev seed 9: its last four moves gained 0.8 of chi^2 1854.3)."""
    return variance_left(fit.chi2, n_rows, _unknowns(fit, n_ribs))


def explained(fit, n_rows: int, n_ribs: int) -> bool:
    """Whether the noise alone explains what ``fit`` leaves (the chi-square test at the diagnosis's
    ALPHA, :func:`pcbdyn.problems.error_budget.noise_explains`): the data then show no sign of a rib in
    the wrong place, and no restart is screened (the bench's six rib cases all end so; housing dev seed 3,
    whose rib a restart moved, at 37 times its rows)."""
    return noise_explains(fit.chi2, n_rows - _unknowns(fit, n_ribs), ALPHA)


def _unknowns(fit, n_ribs: int) -> int:
    """The declared parameters, the magnitudes and the ribs' coordinates that ``fit`` fitted."""
    return np.size(fit.p) + np.size(fit.values) + COORDINATES * n_ribs


def settled(start: float, end: float, strode: bool) -> bool:
    """Whether a round of moves from chi^2 ``start`` to ``end`` ends the fit: it gained less than
    :data:`ROUND_GAIN` of chi^2 (none, where it took no move) and none of the moves it took (``strode``)
    reached its outer place. Smaller gains are the mesh's, not the data's (the housing wall bar's end crept 0.17 mm a move
    for ten rounds, 0.1 % of chi^2 each); but a move taken to its outer place is still striding towards
    a minimum (report seed 1023, far from it: a round of 0.9 % followed by steps that doubled, 46730 to
    43141)."""
    return end >= (1.0 - ROUND_GAIN) * start and not strode


def _fit_at(base, observations, effects, p, values, steps: int):
    """(models, residual, placed, :class:`.fitting.Fit`) of the structure meshed along ``effects``'
    ribs, the declared parameters and magnitudes fitted from ``p``, ``values``; None where it cannot
    be meshed there (a line too close to a part's outline) or the fit cannot start."""
    try:
        models, res, placed = conforming.remeshed(*base, observations, effects)
        fit = estimate(res, p, placed, values, steps, models.bounds)
    except (StructureError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None
    return None if fit.state is None else (models, res, placed, fit)


def _trial(_, effects, values, shared) -> float:
    """One place of a line search or a restart (a job): its chi^2 with the declared parameters and the
    magnitudes fitted from ``values`` (infinite where it cannot be meshed or fitted)."""
    base, observations, p = shared
    out = None if effects is None else _fit_at(base, observations, effects, p, values, TRIAL_STEPS)
    return np.inf if out is None else out[3].chi2


def _solve(base, observations, effects, p, values):
    """(models, residual, placed, state) of the structure meshed along ``effects``' ribs at ``p`` and
    magnitudes ``values``, or None where it cannot be meshed there."""
    try:
        models, res, placed = conforming.remeshed(*base, observations, effects)
        return models, res, placed, res.evaluate(p, placed, values)
    except (StructureError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None


def _with_geometry(chosen, ribs, g, h):
    """``chosen`` with rib ``ribs[n]`` along g[5n:5n+4] (x0, y0, x1, y1) [m] in its plate's plane, of
    section exp(g[5n+4]);
    None where a rib would be shorter than :data:`MIN_LENGTH` elements."""
    out = list(chosen)
    for n, k in enumerate(ribs):
        x0, y0, x1, y1, ln_h = g[5 * n:5 * n + 5]
        if np.hypot(x1 - x0, y1 - y0) < MIN_LENGTH * h:
            return None
        rib = replace(chosen[k], data={**chosen[k].data, "height": float(np.exp(ln_h))})
        out[k] = kind("stiffener").along(rib, np.array([[x0, y0], [x1, y1]]))
    return out


def _difference(_, g, shared):
    """One forward difference (a job): the residual rows at geometry ``g`` (None: not meshed there)."""
    base, observations, chosen, ribs, h, p, values = shared
    effects = _with_geometry(chosen, ribs, g, h)
    out = None if effects is None else _solve(base, observations, effects, p, values)
    return None if out is None else out[3].r


def _gauss_newton(base, observations, chosen, ribs, h, fit, bounds, runner, plates, steps: int = GN_STEPS):
    """(chosen, (models, res, placed, Fit)) after the bounded Gauss-Newton on (ln p, magnitudes, the
    ribs' ends in their plates' planes and ln h) from ``fit`` (module doc), the ends within ``plates``
    [(lowest, highest) corner (2,) [m] per rib]; None where it cannot start."""
    p = np.asarray(fit.p, float)
    npar, ne = p.size, len(chosen)
    g0 = np.concatenate([np.r_[in_plane(chosen[k]).ravel(),
                               np.log(chosen[k].data.get("height", kind("stiffener").section.h))] for k in ribs])
    v_lo = np.array([c.spec.lower for c in chosen], float)
    v_hi = UPPER * np.array([c.spec.scale for c in chosen], float)
    lo_p, hi_p = bounds if bounds is not None else (np.zeros(npar), np.full(npar, np.inf))
    with np.errstate(divide="ignore"):
        lower = np.r_[np.log(np.maximum(lo_p, 1e-6 * np.abs(p))), v_lo,
                      np.concatenate([np.r_[lo, lo, np.log(HEIGHT[0])] for lo, _ in plates])]
        upper = np.r_[np.log(hi_p), v_hi, np.concatenate([np.r_[hi, hi, np.log(HEIGHT[1])] for _, hi in plates])]
    scale = np.r_[np.ones(npar), [c.spec.scale for c in chosen], np.tile([h, h, h, h, 1.0], len(ribs))]
    step = np.tile(np.r_[np.full(4, STEP * h), HEIGHT_STEP], len(ribs))
    standing: list = []  # [(y, effects, solved)] of the state the fit stands on: trials it does not take are let go

    def evaluate(y):
        effects = _with_geometry(chosen, ribs, y[npar + ne:], h)
        out = None if effects is None else _solve(base, observations, effects, np.exp(y[:npar]), y[npar:npar + ne])
        if out is not None and all(taken(out[3].chi2, now[2][3].chi2) for now in standing):
            standing[:] = [(y.copy(), effects, out)]  # each re-meshed model holds its mesh, residual and caches
        return None if out is None else out[3]

    def jacobian(st):
        y, _, (_, res, placed, _) = standing[0]
        jobs = [(y[npar + ne:] + step[j] * np.eye(step.size)[j],) for j in range(step.size)]
        rows = runner.map(_difference, jobs, (base, observations, chosen, ribs, h, np.exp(y[:npar]), y[npar:npar + ne]),
                          "re-meshed trials of the ribs' ends")
        fd = np.column_stack([np.zeros(st.r.size) if r is None or r.size != st.r.size else -(r - st.r) / step[j]
                              for j, r in enumerate(rows)])
        return np.hstack(([res.param_columns(st)] if npar else []) + [res.effect_columns(st, placed), fd])

    y0 = np.r_[np.log(p), np.clip(np.asarray(fit.values, float), v_lo, v_hi), g0]
    gn = gauss_newton(evaluate, jacobian, y0, lower, upper, scale, steps,
                      lambda y: np.r_[1e-4 * np.ones(npar), 1e-4 * scale[npar:npar + ne], 0.05 * step], DAMPING)
    if gn.state is None:
        return None
    y, effects, (models, res, placed, st) = standing[0]
    n = npar + ne
    return effects, (models, res, placed, Fit(np.exp(y[:npar]), y[npar:n], st, gn.cov[:n, :n]))


def fit_ribs(structure, configs, names, h: float, observations, chosen: list, p, values, runner, say=None,
             rounds: int = ROUNDS) -> Ribs | None:
    """The stiffeners of ``chosen`` moved to where they fit best (module doc), from the declared
    parameters ``p`` and all magnitudes ``values``; None where ``chosen`` has no stiffener or the
    structure cannot be meshed along them. ``runner`` runs the re-meshed trials."""
    ribs = [k for k, c in enumerate(chosen) if c.kind == "stiffener"]
    base = (structure, configs, names, h)
    here = _fit_at(base, observations, chosen, p, values, conforming.STEPS) if ribs else None
    if here is None:
        return None
    layout = from_structure(here[0].models[0])
    plates = [extent(in_its_plane(layout, chosen[k].data.get("plate"))[0]) for k in ribs]
    gn = _gauss_newton(base, observations, chosen, ribs, h, here[3], here[0].bounds, runner, plates)
    if gn is not None and gn[1][3].chi2 < here[3].chi2:
        chosen, here = gn
        if say:
            say(f"  ends and sections by Gauss-Newton: chi^2 {here[3].chi2:.5g}")
    chosen, here = _walk(base, observations, chosen, ribs, here, h, runner, say, rounds)
    for _ in range(SCREENS):
        better = _restarted(base, observations, chosen, ribs, here, h, runner)
        if better is None:
            break
        chosen, here = better
        if say:
            say(f"  restarted from {', '.join(chosen[k].name for k in ribs)}: chi^2 {here[3].chi2:.5g}")
        chosen, here = _walk(base, observations, chosen, ribs, here, h, runner, say, rounds)
    return Ribs(*here)


def restarts(rib, h: float) -> list:
    """[(rib, factor of its EI)] the places ``rib`` restarts from (:data:`RESTARTS` at its height and at it
    times and over :data:`HEIGHT_LADDER`; its EI scaled as its length and by :data:`EI_STARTS`), where
    they are at least :data:`MIN_LENGTH` elements long and their height within :data:`HEIGHT`."""
    path, height = in_plane(rib), rib.data.get("height", kind("stiffener").section.h)
    out = []
    for a, b in RESTARTS:
        piece = path[0] + np.array([[a], [b]]) * (path[1] - path[0])
        for f in (1.0 / HEIGHT_LADDER, 1.0, HEIGHT_LADDER):
            if (there := _on(rib, piece, f * height, h)) is not None:
                out += [(there, g / (b - a)) for g in EI_STARTS]
    return out


def _restarted(base, observations, chosen, ribs, here, h, runner):
    """(chosen, (models, res, placed, Fit)) at the best of the ribs' :func:`restarts` where it lowers chi^2
    by more than the data resolve (:func:`resolved`), else None (and none screened where the noise
    explains ``here``: :func:`explained`)."""
    fit, jobs = here[3], []
    if explained(fit, here[1].n_rows, len(ribs)):
        return None
    for k in ribs:
        for rib, factor in restarts(chosen[k], h):
            values = np.array(fit.values, float)
            values[k] *= factor
            jobs.append(([*chosen[:k], rib, *chosen[k + 1:]], values))
    chi2 = runner.map(_trial, jobs, (base, observations, fit.p), "restarts of the ribs")
    need = resolved(fit, here[1].n_rows, len(ribs))
    best = int(np.argmin(chi2)) if jobs else None
    if best is None or not chi2[best] < fit.chi2 - need:
        return None
    effects, values = jobs[best]
    trial = _fit_at(base, observations, effects, fit.p, values, conforming.STEPS)
    return None if trial is None or not trial[3].chi2 < fit.chi2 - need else (effects, trial)


def _walk(base, observations, chosen, ribs, here, h, runner, say, rounds: int):
    """(chosen, (models, res, placed, Fit)) after the rounds of line searches over :data:`MOVES` (module
    doc) from ``chosen`` at ``here``."""
    step = {(k, m): s for k in ribs for m, s in MOVES.items()}
    for _ in range(rounds):
        start, strode = here[3].chi2, False
        for k in ribs:
            for m in MOVES:
                scale = 1.0 if m == "height" else h
                d = step[(k, m)] * scale
                sides = [moved(chosen[k], m, -d, h), moved(chosen[k], m, d, h)]
                fit = here[3]
                chi2 = runner.map(_trial, [(None if s is None else [*chosen[:k], s, *chosen[k + 1:]], fit.values)
                                           for s in sides], (base, observations, fit.p), f"places of {chosen[k].name}")
                places = ([-d, 0.0, d], [chi2[0], fit.chi2, chi2[1]])
                x = vertex(*places)
                lo, hi = (MOVES[m] * f for f in STEP_RANGE)
                outer = abs(x) >= d * (1 - 1e-9)
                step[(k, m)] = float(np.clip(step[(k, m)] * (2.0 if outer else 0.5), lo, hi))
                need = resolved(fit, here[1].n_rows, len(ribs))
                there = None if x == 0.0 or fit.chi2 - parabola(*places, x) < need else moved(chosen[k], m, x, h)
                trial = None if there is None else _fit_at(base, observations, [*chosen[:k], there, *chosen[k + 1:]],
                                                           fit.p, fit.values, conforming.STEPS)
                if trial is not None and trial[3].chi2 < fit.chi2 - need:
                    chosen, here, strode = [*chosen[:k], there, *chosen[k + 1:]], trial, strode or outer
                    if say:
                        by = f"{x:+.3g} in ln h" if m == "height" else f"{1e3 * x:+.3g} mm"
                        say(f"  {chosen[k].name}: {m} {by}, chi^2 {trial[3].chi2:.5g}")
        if settled(start, here[3].chi2, strode):
            break
    return chosen, here
