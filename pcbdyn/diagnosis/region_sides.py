"""The sides of rectangular regions fitted as continuous coordinates (issue 37).

A region covers each cell by the share of it inside its rectangle (:mod:`.region_stiffness`), so K,
and the residual, move continuously with its sides. The local search (:func:`.select.refine`) walks a
rectangle by whole elements; the data fix a region's change times its area better than either, so
the walk stops where one more element costs more than it gains, often smaller and stiffer than the
region (discovery benchmark, dev seed 20: a stiffening of 1.99 over 24 x 26 mm, stopped at 4.67 over
14 x 21 mm, chi^2 467 there and 466 at 1.4 times its sides, 483 at 1.2 on cells taken whole). Here the
four sides of every rectangular region are fitted with the declared parameters and all magnitudes by
the bounded Gauss-Newton of the updating engine (thesis ch. 4, the bounds of eqs. 4.44-4.48), with
Marquardt's damped steps where the halved ones fail, as the ribs' ends are (:mod:`.geometry_fit`).
The sides' columns are forward differences of :data:`STEP` elements on the same mesh, taken at a
fixed integral of the change over the region (the magnitude a region moved to another rectangle
starts from, :func:`.catalogue.moved_value`): at a fixed change, a side's move of a few mm changed
chi^2 a hundredfold on a heat sink 8 times as stiff, and the steps failed.

The sides found are kept only where chi^2 falls by more than one unit per side freed, in units of the
variance the fit leaves where that exceeds the stated noise: what freeing them gains on noise alone,
on average (a 4 x 4 element softening, frequencies of 8 modes at 0.2 % noise: the sides fitted took
chi^2 from 4.2 to 0.9 and the change from -0.50, the truth, to -0.66).
"""

from __future__ import annotations

import numpy as np

from ..updating.gauss_newton import DAMPING, gauss_newton
from .catalogue import jointly, moved_value
from .fitting import UPPER, Fit
from .moves import RECT_STEP, rectangle

#: [element sizes] the forward-difference step of a side
STEP = 0.125
#: Gauss-Newton steps (each 1 + 4 solves per region, and halvings)
STEPS = 8
#: [element sizes] the narrowest a fitted rectangle may become along either axis, as the walk's (a region
#: narrower than a cell is spread over the cells it cuts: dev seed 12's stiffening of 1.28 over 19 x 28 mm
#: on an 8 mm mesh went to 11.3 over 4.4 x 16 mm with half an element allowed)
MIN_WIDTH = RECT_STEP


def fit_sides(res, candidates: list, idx: list, fit: Fit, moves, bounds=None, steps: int = STEPS) -> tuple:
    """(idx, fit) with the rectangular regions among ``candidates[idx]`` moved to the sides that fit
    best (module doc), or the ones given where the data do not resolve the move; ``moves``: the
    :class:`.moves.LocalMoves` whose layout the regions lie on (the rectangle found is appended to
    ``candidates`` through it)."""
    layout, h = moves.layout, moves.h
    boxes = [rectangle(candidates[i]) for i in idx]
    # the halves of a body (a heat sink's stiffness and mass) lie on one rectangle: it moves as one
    rects = list(dict.fromkeys(tuple(np.round(b, 9)) for b in boxes if b is not None))
    regions = [(k, rects.index(tuple(np.round(b, 9)))) for k, b in enumerate(boxes) if b is not None]
    if not regions or not layout.planar or fit.state is None:
        return idx, fit
    cands = [candidates[i] for i in idx]
    p = np.asarray(fit.p, float)
    npar, ne, nb = p.size, len(idx), 4 * len(rects)
    lo_v = np.array([c.spec.lower for c in cands], float)
    hi_v = UPPER * np.array([c.spec.scale for c in cands], float)
    lo_p, hi_p = bounds if bounds is not None else (np.zeros(npar), np.full(npar, np.inf))
    with np.errstate(divide="ignore"):
        lower = np.r_[np.log(np.maximum(lo_p, 1e-6 * np.abs(p))), lo_v, np.tile(np.r_[moves.lo, moves.lo], len(rects))]
        upper = np.r_[np.log(hi_p), hi_v, np.tile(np.r_[moves.hi, moves.hi], len(rects))]
    scale = np.r_[np.ones(npar), [c.spec.scale for c in cands], np.full(nb, h)]
    step = STEP * h
    made: dict = {}  # id(state) -> (y, the effects there, state) of the trials since the last Jacobian

    def factors(effects) -> np.ndarray:
        """d(magnitude)/d(its variable) at ``effects``: each variable is the magnitude the effect would have
        on its starting rectangle (a stiffness change's integral over the area, a mass), so that a move
        of the sides alone keeps what the data fix best (:func:`.catalogue.moved_value`)."""
        return np.array([moved_value(c, e, 1.0) for c, e in zip(cands, effects)])

    def placed(g):
        out = list(cands)
        for k, n in regions:
            box = g[4 * n:4 * n + 4]
            if min(box[2] - box[0], box[3] - box[1]) < MIN_WIDTH * h:
                return None
            out[k] = cands[k].spec.rectangle(layout, *box)
            if out[k] is None:
                return None
        return out

    def solve(y):
        effects = placed(y[npar + ne:])
        if effects is None:
            return None
        f = factors(effects)
        v = f * y[npar:npar + ne]
        if not (np.all((v >= lo_v) & (v <= hi_v)) and jointly(effects)(v)):
            return None
        try:
            st = res.evaluate(np.exp(y[:npar]), effects, v)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):
            return None
        return (effects, st) if np.isfinite(st.r).all() else None

    def evaluate(y):
        out = solve(y)
        if out is None:
            return None
        made[id(out[1])] = (y.copy(), *out)
        return out[1]

    def jacobian(st):
        y, effects, _ = here = made[id(st)]
        made.clear()
        made[id(st)] = here
        cols = ([res.param_columns(st)] if npar else []) + [res.effect_columns(st, effects) * factors(effects)]
        for j in range(nb):
            moved = solve(y + step * np.eye(y.size)[npar + ne + j])
            cols.append(np.zeros((st.r.size, 1)) if moved is None else ((st.r - moved[1].r) / step)[:, None])
        return np.hstack(cols)

    y0 = np.r_[np.log(p), np.clip(np.asarray(fit.values, float), lo_v, hi_v), np.concatenate(rects)]
    gn = gauss_newton(evaluate, jacobian, y0, lower, upper, scale, steps,
                      lambda y: np.r_[1e-4 * np.ones(npar), 1e-4 * scale[npar:npar + ne], 0.05 * np.full(nb, step)],
                      DAMPING)
    if gn.state is None or not fit.chi2 - gn.chi2 > nb * max(gn.chi2 / max(res.n_rows - npar - ne - nb, 1), 1.0):
        return idx, fit
    y, effects, st = made[id(gn.state)]
    out = list(idx)
    for k, n in regions:
        out[k] = moves.region(cands[k].kind, y[npar + ne + 4 * n:npar + ne + 4 * n + 4])
    d = np.r_[np.ones(npar), factors(effects)]
    return out, Fit(np.exp(y[:npar]), d[npar:] * y[npar:npar + ne], st, d[:, None] * gn.cov[:npar + ne, :npar + ne] * d)
