"""Overlapping or side-by-side regions found that are one region (issue 37). Forward selection places
regions on a grid of rectangles; a region between them is fitted as two or three overlapping ones,
whose changes add where they overlap, and a region across two of them as the two side by side.
Reported as their union with the area-weighted mean change (:func:`.merge.merged`, which keeps the
change's integral), an overlapping group misstates both: the union is larger than the region and the
mean change smaller; and a region split in two pays the penalty twice. Each group is therefore
refitted as one rectangle, started from the members' intersection (where it has an area), their
bounding box and each member's own rectangle, the best of them walked by its sides
(:func:`.select.refine`), and kept where the information criterion of :mod:`.select` does not rise:
one effect instead of several, each of which paid a penalty. Where it rises, overlapping regions are
still reported as one (:func:`.merge.linked`), side-by-side ones as two."""

from __future__ import annotations

import numpy as np
import shapely

from .merge import groups, linked
from .moves import REGION_KINDS, overlap, rectangle
from .fitting import estimate
from .select import refine
from .selection import ALPHA, Selection, adopt, penalty

#: [m] rectangles this close along an axis touch there (their sides lie on one grid line)
TOUCH = 1e-9


def starts(boxes, values, name: str) -> list:
    """[(rectangle, starting magnitude)] for one region standing for the overlapping ``boxes`` of kind
    ``name`` with their ``values``: their intersection (where it has an area), their bounding box and
    each box; a stiffness change starts at the members' mean change over the rectangle (changes add
    where regions overlap), a mass at the members' masses in it (each spread over its own box)."""
    b = np.asarray(boxes, float)
    members = [shapely.box(*m) for m in b]
    tried = [(*b[:, :2].max(axis=0), *b[:, 2:].min(axis=0)), (*b[:, :2].min(axis=0), *b[:, 2:].max(axis=0))]
    tried += [tuple(x) for x in b]
    out = []
    for box in tried:
        rect = shapely.box(*box)
        if not (box[2] > box[0] and box[3] > box[1]) or any(np.allclose(box, o) for o, _ in out):
            continue
        share = np.array([rect.intersection(m).area for m in members])
        per = share / rect.area if name == "region_stiffness" else share / np.array([m.area for m in members])
        out.append((tuple(float(x) for x in box), float(per @ np.asarray(values, float))))
    return out


def as_one_region(res, candidates: list, sel: Selection, moves, reach: float, bounds=None, newton_steps: int = 8,
                  alpha: float = ALPHA, runner=None) -> Selection:
    """``sel`` with each group of overlapping or side-by-side rectangular regions of one kind
    (:func:`.merge.groups`, ``reach`` [m]) replaced by one rectangle where that does not raise the
    criterion (module doc); ``moves``: the :class:`.moves.LocalMoves` that make the rectangles
    (appended to ``candidates``) and walk them. ``sel`` is updated in place."""
    if not moves.layout.planar:
        return sel
    merged = True
    while merged:
        chosen = [candidates[i] for i in sel.chosen]
        merged = any(_one(res, candidates, sel, g, moves, bounds, newton_steps, alpha, runner)
                     for g in groups(chosen, reach, _one_region) if len(g) > 1 and chosen[g[0]].kind in REGION_KINDS
                     and all(rectangle(chosen[k]) is not None for k in g))
    return sel


def side_by_side(a, b) -> bool:
    """Rectangular regions of one kind that share part of a side (not a corner only), [m] to within
    :data:`TOUCH`. Tried as one region, but reported as two where that fit is refused: changes that
    differ on either side of a line are two regions (dev seed 22: a stiffening of 18, a heat sink,
    beside one of 1.4)."""
    if a.kind != b.kind or a.kind not in REGION_KINDS or None in (ra := rectangle(a), rb := rectangle(b)):
        return False
    common = overlap(ra, rb)
    return min(common) >= -TOUCH and max(common) > TOUCH


def _one_region(a, b, reach: float) -> bool:
    """Two chosen effects tried as one region: linked as reported (:func:`.merge.linked`: overlapping
    rectangles) or side by side."""
    return linked(a, b, reach) or side_by_side(a, b)


def _one(res, candidates, sel, g, moves, bounds, newton_steps, alpha, runner) -> bool:
    """Whether group ``g`` (positions in ``sel.chosen``) became one rectangle (``sel`` updated)."""
    name = candidates[sel.chosen[g[0]]].kind
    others = [k for k in range(len(sel.chosen)) if k not in g]
    idx = [sel.chosen[k] for k in others]
    kept, values = np.asarray(sel.values, float)[others], np.asarray(sel.values, float)[g]
    best = None
    for box, v0 in starts([rectangle(candidates[sel.chosen[k]]) for k in g], values, name):
        j = moves.region(name, box)
        if j is None:
            continue
        v0 = max(v0, 0.9 * candidates[j].spec.lower)  # overlapping softenings may add below the kind's bound
        fit = estimate(res, sel.p, [candidates[i] for i in idx + [j]], np.r_[kept, v0], newton_steps, bounds)
        if best is None or fit.chi2 < best[1].chi2:
            best = (j, fit)
    if best is None:
        return False
    pen = penalty(res.n_rows, len(candidates), alpha)
    held = set(idx)  # the other effects stay where they are; the rectangle walks
    trial = refine(res, candidates, adopt(Selection(), idx + [best[0]], best[1], pen),
                   lambda i: [] if i in held else moves(i), bounds, newton_steps, alpha=alpha, runner=runner)
    if trial.chi2[-1] + len(trial.chosen) * pen > sel.chi2[-1] + len(sel.chosen) * pen:
        return False
    fit = estimate(res, trial.p, [candidates[i] for i in trial.chosen], trial.values, newton_steps, bounds)
    adopt(sel, trial.chosen, fit, pen)
    return True
