"""Point masses found that are one mass spread along a line (a cable, a harness, a bar's mass across the
board; issue 37). A uniform line of mass m and length L has the mass, the centre and the second moments
about its centre of two masses m / 2 at L / (2 sqrt 3) either side of the centre (the two-point Gauss
rule of the line), so the low modes hardly tell the two apart, and forward selection, which adds one
point at a time, finds the pair (or one of them as a body with an inertia, :mod:`.bodies`, or a mass
over a patch of the regions' grid). Each two masses found are tried as the line through them, sqrt 3
times as long as they are apart, carrying their summed mass; its ends are then walked to where the data
put them (the pair stood on nodes), and the line replaces the pair where it lowers the information
criterion of :mod:`.select` (one effect instead of two or three; two unequal masses apart fit the line
worse, and stay). A line the search found as one mass (its centre; a body whose inertia stands for the
line's second moment) is tried as lines through that centre in four directions and several lengths from
one element up, the best walked the same way; it must lower the criterion by one effect's penalty more,
as its direction and length are two coordinates a point does not have, and both the best line tried and
the walked one must be at least two elements long: a shorter line is not one the mesh resolves, and a
mass the data want spread over less than that is the coarse mesh's way of holding a point (dev seed 0's
50 g point mass had become a 7.8 mm line on 6 mm elements; hold-out ``ho_mass_card``'s 18 g point mass,
whose lines through it fit best at one element long, was walked from two elements to a 15 mm line on
6.75 mm elements). The same walk places a mass or a spring to ground found on nodes at its point between
them (:mod:`.at_points`)."""

from __future__ import annotations

from itertools import combinations

import numpy as np

from .catalogue import weighted_centre
from .fitting import RANK_STEPS, estimate, pattern_search
from .line_mass import KIND
from .merge import groups
from .reanalysis import Reanalysis
from .selection import ALPHA, adopt, penalty

#: a line's length over the distance between the two point masses that stand in for it
SPREAD = np.sqrt(3.0)
#: lengths a line standing for one mass is first tried at (each sqrt 2 times the one before, from one
#: element for a point mass: sixteen elements the longest)
LENGTHS = 9
#: the kinds of mass found that may stand for a line: a point (or its shares), and a mass spread over a
#: region, the catalogue's other spread mass, which the search picks for a short line across the plate
#: (dev seed 11: a 4.5 g line 28 mm long across a card came out as 4.2 g over a 20 mm patch at its middle)
LINE_LIKE = ("point_mass", "region_mass")


def masses_found(chosen, values, groups) -> list:
    """[(positions in ``chosen`` of one mass found: a group of point-mass shares, a mass over a region,
    or a body of :mod:`.bodies` with its inertia (the two share the body's ``centre``), positions of its
    mass, the mass, its centre (2,) [m])]; ``values``: the chosen effects' magnitudes."""
    v = np.asarray(values, float)
    out = []
    for g in groups:
        if not all(chosen[k].kind in LINE_LIKE for k in g):
            continue
        bodies = {chosen[k].data["centre"] for k in g if "radius" in chosen[k].data}
        inertias = [k for k, c in enumerate(chosen) if c.kind == "point_inertia" and c.data.get("centre") in bodies]
        out.append((g + inertias, g, float(v[g].sum()), weighted_centre([chosen[k] for k in g], v[g])[:2]))
    return out


def _pairs(candidates, sel, groups) -> list:
    """[(candidate indices of both masses (a body's inertia with its mass), their summed mass, the
    line's ends (2, 2) [m])] for every two masses found, nearest first."""
    chosen = [candidates[i] for i in sel.chosen]
    out = []
    for (g, _, ma, a), (h, _, mb, b) in combinations(masses_found(chosen, sel.values, groups), 2):
        mid, half = 0.5 * (a + b), 0.5 * SPREAD * (b - a)
        out.append(([sel.chosen[k] for k in g + h], ma + mb, np.array([mid - half, mid + half])))
    return sorted(out, key=lambda t: float(np.linalg.norm(t[2][1] - t[2][0])))


def _lines(layout):
    """The lines a pattern search tries: ends (x0, y0, x1, y1) [m] -> [the line mass across ``layout``'s
    plate], None where it misses the plate or its ends meet."""
    def build(ends):
        ends = np.reshape(ends, (2, 2))
        line = None if np.linalg.norm(ends[1] - ends[0]) < 1e-6 else KIND.across(layout, *ends)
        return None if line is None else [line]
    return build


def _singles(candidates, sel, groups, h: float, reach: float) -> list:
    """[(candidate indices of one mass found (a body's inertia with its mass), its mass, centre (2,)
    [m], the length a line standing for it starts at)]: a body's radius of gyration r gives the line
    of the same rotary inertia averaged over the two in-plane axes (m L^2 / 24 = m r^2); a point
    mass, one element. A mass with a spring to ground found within ``reach`` [m] is a bracket (a
    mass held by a spring), not a line, and is left out."""
    chosen = [candidates[i] for i in sel.chosen]
    springs = np.array([c.at[:2] for c in chosen if c.kind == "ground_spring"], float).reshape(-1, 2)
    out = []
    for g, gm, m, centre in masses_found(chosen, sel.values, groups):
        if (np.linalg.norm(springs - centre, axis=1) <= reach).any():
            continue
        radius = max((chosen[k].data.get("radius", 0.0) for k in gm), default=0.0)
        out.append(([sel.chosen[k] for k in g], m, centre, max(np.sqrt(24.0) * radius, h)))
    return out


def _oriented(res, sel, rest, values, m, centre, length, layout, bounds) -> tuple:
    """(ends (2, 2) [m], chi^2) of the line through ``centre`` that fits best of four directions (0,
    45, 90, 135 degrees) and :data:`LENGTHS` lengths from ``length`` up, by quick fits reduced to the
    selection's solved state (:class:`.reanalysis.Reanalysis`; the mass it stands for goes to zero);
    ends None where none lies on the plate."""
    rx, P = Reanalysis(res, sel.state), res.param_columns(sel.state)
    best, ends = np.inf, None
    for a, L in ((a, length * 2.0 ** (k / 2)) for a in np.deg2rad([0.0, 45.0, 90.0, 135.0]) for k in range(LENGTHS)):
        half = 0.5 * L * np.array([np.cos(a), np.sin(a)])
        e = np.array([centre - half, centre + half])
        line = KIND.across(layout, *e)
        if line is None:
            continue
        trial = estimate(res, sel.p, rest + [line], np.r_[values, m], RANK_STEPS, bounds, param_columns=P, reduced=rx)
        if trial.state is not None and trial.chi2 < best:
            best, ends = trial.chi2, e
    return ends, best


def _as_line(res, candidates, sel, replaced, m, ends, layout, step, bounds, newton_steps, pen, extra: float,
             shortest: float = 0.0) -> bool:
    """Replace the chosen effects ``replaced`` (candidate indices) by one line mass of mass ``m``
    starting at ``ends``, walked (:func:`walked_in`), where the criterion drops by more than ``extra``
    and the walked line is at least ``shortest`` [m] long; True when it did."""
    line = KIND.across(layout, *ends)
    return line is not None and walked_in(res, candidates, sel, replaced, m, line, np.ravel(line.geometry["segment"]),
                                           _lines(layout), step, bounds, newton_steps, pen, extra,
                                           lambda c: c.data["length"] >= shortest)


def walked_in(res, candidates, sel, replaced, m, first, x, build, step, bounds, newton_steps, pen, extra: float,
               keep=lambda c: True) -> bool:
    """Replace the chosen effects ``replaced`` (candidate indices) by one mass ``m`` of candidate
    ``first``, whose geometry is the coordinates ``x`` (``build(x)``: [the candidate there]), walked
    (:func:`.fitting.pattern_search`, quick fits reduced to its fitted state where it starts: a walk is
    hundreds of them), where the criterion drops by more than ``extra`` and ``keep`` (the walked
    candidate) holds; True when it did (``sel`` updated in place, the candidate appended to
    ``candidates``)."""
    pos = {i: k for k, i in enumerate(sel.chosen)}
    others = [i for i in sel.chosen if i not in replaced]
    rest = [candidates[i] for i in others]
    fit = estimate(res, sel.p, rest + [first], np.r_[[sel.values[pos[i]] for i in others], m], newton_steps, bounds)
    if fit.state is None or not fit.values[-1] > 0:
        return False
    rx, P = Reanalysis(res, fit.state), res.param_columns(fit.state)
    # the walk compares reduced fits with a reduced fit, not with the full one
    start = estimate(res, fit.p, rest + [first], fit.values, RANK_STEPS, bounds, param_columns=P, reduced=rx)
    x, quick = pattern_search(res, rest, x, build, start, step, 3, bounds, reduced=rx, param_columns=P)
    made = build(x)
    if made is None or not keep(made[0]):
        return False
    fit = estimate(res, quick.p, rest + made, quick.values, newton_steps, bounds)
    if fit.state is None or not fit.values[-1] > 0 or not fit.chi2 + (len(others) + 1) * pen + extra < sel.criterion[-1]:
        return False
    candidates.append(made[0])
    adopt(sel, others + [len(candidates) - 1], fit, pen)
    return True


def as_lines(res, candidates: list, sel, reach: float, layout, step: float, bounds=None, newton_steps: int = 8,
             alpha: float = ALPHA):
    """``sel`` with each pair of chosen masses (:data:`LINE_LIKE`; groups of effects within ``reach`` [m], reported
    as one: :func:`.merge.groups`) refitted as one line mass across ``layout``'s plate (module doc), its ends
    walked from steps of ``step`` [m] (half the model's element size), where that lowers the criterion; then
    each mass left alone tried as lines through its centre, the best walked where it already fits better than
    the mass and is two elements long or more, and kept where the criterion drops by one effect's penalty more
    and it ends two elements long or more (module doc). Line candidates are appended to ``candidates``;
    ``sel`` is updated in place."""
    if not layout.planar:
        return sel
    pen = penalty(res.n_rows, len(candidates), alpha)

    def mass_groups():
        return groups([candidates[i] for i in sel.chosen], reach)

    for pair, m, ends in _pairs(candidates, sel, mass_groups()):
        if set(pair) <= set(sel.chosen) and m > 0:  # not a mass already taken by another line
            _as_line(res, candidates, sel, pair, m, ends, layout, step, bounds, newton_steps, pen, 0.0)
    h = 2.0 * step  # the element size
    shortest = 2.0 * h  # the shortest line the mesh tells from a point, tried or walked
    for single, m, centre, length in _singles(candidates, sel, mass_groups(), h, reach):
        if not (set(single) <= set(sel.chosen) and m > 0):
            continue
        pos = {i: k for k, i in enumerate(sel.chosen)}
        others = [i for i in sel.chosen if i not in single]
        ends, chi2 = _oriented(res, sel, [candidates[i] for i in others], [sel.values[pos[i]] for i in others], m,
                               centre, length, layout, bounds)
        # walked only where it fits better than the mass and is long enough for the mesh to tell from a point
        if ends is not None and chi2 < sel.chi2[-1] and np.linalg.norm(ends[1] - ends[0]) >= shortest * (1 - 1e-9):
            _as_line(res, candidates, sel, single, m, ends, layout, step, bounds, newton_steps, pen, pen, shortest)
    return sel
