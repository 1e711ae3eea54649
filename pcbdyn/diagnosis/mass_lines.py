"""Two point masses found apart that are one mass spread along a line (a cable, a harness, a bar's
mass across the board; issue 37). A uniform line of mass m and length L has the mass, the centre and
the second moments about its centre of two masses m / 2 at L / (2 sqrt 3) either side of the centre
(the two-point Gauss rule of the line), so the low modes hardly tell the two apart, and forward
selection, which adds one point at a time, finds the pair (or one of them as a body with an inertia,
:mod:`.bodies`). Each two masses found are tried as the line through them, sqrt 3 times as long as
they are apart, carrying their summed mass; its ends are then walked to where the data put them (the
pair stood on nodes), and the line replaces the pair where it lowers the information criterion of
:mod:`.select` (one effect instead of two or three; two unequal masses apart fit the line worse, and
stay)."""

from __future__ import annotations

from itertools import combinations

import numpy as np

from .catalogue import weighted_centre
from .fitting import RANK_STEPS, estimate
from .line_mass import KIND
from .select import ALPHA, adopt, penalty

#: a line's length over the distance between the two point masses that stand in for it
SPREAD = np.sqrt(3.0)


def _masses(chosen, groups) -> list:
    """[(positions in ``chosen`` of one mass found: a group of point-mass shares, or a body of
    :mod:`.bodies` with its inertia (the two share the body's ``centre``), positions of its mass)]."""
    out = []
    for g in groups:
        if not all(chosen[k].kind == "point_mass" for k in g):
            continue
        bodies = {chosen[k].data["centre"] for k in g if "radius" in chosen[k].data}
        inertias = [k for k, c in enumerate(chosen) if c.kind == "point_inertia" and c.data.get("centre") in bodies]
        out.append((g + inertias, g))
    return out


def _pairs(candidates, sel, groups) -> list:
    """[(candidate indices of both masses (a body's inertia with its mass), their summed mass, the
    line's ends (2, 2) [m])] for every two masses found, nearest first."""
    chosen = [candidates[i] for i in sel.chosen]
    v = np.asarray(sel.values, float)
    out = []
    for (g, gm), (h, hm) in combinations(_masses(chosen, groups), 2):
        a, b = (weighted_centre([chosen[k] for k in q], v[q])[:2] for q in (gm, hm))
        mid, half = 0.5 * (a + b), 0.5 * SPREAD * (b - a)
        out.append(([sel.chosen[k] for k in g + h], float(v[gm + hm].sum()), np.array([mid - half, mid + half])))
    return sorted(out, key=lambda t: float(np.linalg.norm(t[2][1] - t[2][0])))


def _walk(res, others, line, fit, layout, step: float, bounds):
    """(line, fit) with each end moved by a pattern search (steps of ``step`` [m] along x and y while
    chi^2 drops, then halved, down to ``step`` / 4; quick fits)."""
    ends = np.asarray(line.geometry["segment"], float)
    for s in step / 2.0 ** np.arange(3):
        moved = True
        while moved:
            moved = False
            for k, d in ((k, d) for k in (0, 1) for d in ((s, 0.0), (-s, 0.0), (0.0, s), (0.0, -s))):
                trial_ends = ends.copy()
                trial_ends[k] += d
                trial_line = KIND.across(layout, *trial_ends)
                if trial_line is None:
                    continue
                trial = estimate(res, fit.p, others + [trial_line], fit.values, RANK_STEPS, bounds)
                if trial.state is not None and trial.chi2 < fit.chi2 * (1.0 - 1e-6):
                    line, fit, ends, moved = trial_line, trial, trial_ends, True
                    break
    return line, fit


def as_lines(res, candidates: list, sel, groups, layout, step: float, bounds=None, newton_steps: int = 8,
             alpha: float = ALPHA):
    """``sel`` with each pair of chosen point-mass groups (``groups``: lists of positions in
    ``sel.chosen`` reported as one effect) refitted as one line mass across ``layout``'s plate (module
    doc), its ends walked from steps of ``step`` [m], where that lowers the criterion. Line candidates
    are appended to ``candidates``; ``sel`` is updated in place."""
    if not layout.planar:
        return sel
    pen = penalty(res.n_rows, len(candidates), alpha)
    for pair, m, ends in _pairs(candidates, sel, groups):
        if not set(pair) <= set(sel.chosen) or not m > 0:  # a mass already taken by another line
            continue
        line = KIND.across(layout, *ends)
        if line is None:
            continue
        pos = {i: k for k, i in enumerate(sel.chosen)}
        others = [i for i in sel.chosen if i not in pair]
        rest = [candidates[i] for i in others]
        fit = estimate(res, sel.p, rest + [line], np.r_[[sel.values[pos[i]] for i in others], m], newton_steps, bounds)
        if fit.state is None or not fit.values[-1] > 0:
            continue
        line, quick = _walk(res, rest, line, fit, layout, step, bounds)
        fit = estimate(res, quick.p, rest + [line], quick.values, newton_steps, bounds)
        if fit.state is None or not fit.values[-1] > 0 or not fit.chi2 + (len(others) + 1) * pen < sel.criterion[-1]:
            continue
        candidates.append(line)
        adopt(sel, others + [len(candidates) - 1], fit, pen)
    return sel
