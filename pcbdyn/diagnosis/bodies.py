"""A part found as a point mass with a rotary inertia beside it is one rigid body (issue 7): its
mass and inertia are refitted together at one point, moving with the disc of the body's radius of
gyration r = sqrt(J / m) (as a board's ``[[masses]]`` entry with both, so the enriched board.toml
builds the model that was fitted).

Forward selection finds the two separately, the inertia alone at some node nearby (on a disc of
fixed size, where a body that wide would act on the plate's slope), the mass often as shares on the nodes
around it. Here the pair becomes two candidates at the mass shares' centre with the footprint of radius r
(:mod:`.point_mass`); r depends on the magnitudes, so the fit is repeated with r updated until it
settles (a fixed point; each fit is linear in m and J at fixed r), and the centre is moved to
where the data put it. The body replaces the pair when it lowers the information criterion of
:mod:`.select`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .catalogue import weighted_centre
from .fitting import estimate, pattern_search
from .selection import ALPHA, adopt, penalty

#: fixed-point iterations on the radius of gyration, and the relative change that ends them
RADIUS_ITERATIONS, RADIUS_TOL = 5, 0.02


def _body(home, centre, radius: float) -> tuple:
    """(mass, inertia) candidates of a body of radius of gyration ``radius`` [m] centred at
    ``centre`` (x, y, z) [m], built from ``home``, the point-mass candidate nearest to it. The
    name holds the geometry (to 0.01 mm): models and derivatives are cached by name."""
    data = {**home.data, "radius": float(radius), "centre": tuple(map(float, centre))}
    geometry = {**home.geometry, "radius": float(radius)}
    at = (float(centre[0]), float(centre[1]))
    name = f"body@{1e3 * at[0]:.2f},{1e3 * at[1]:.2f}mm/r{1e3 * radius:.2f}mm"
    return (replace(home, name=f"{name}:mass", at=at, data=data, geometry=geometry),
            replace(home, kind="point_inertia", name=f"{name}:inertia", at=at, data=data, geometry=geometry))


def _pairs(candidates, sel, groups, reach: float) -> list:
    """[(mass candidate indices, inertia candidate indices, centre)]: each group of chosen point
    masses with the nearest group of chosen point inertias within ``reach``."""
    chosen = [candidates[i] for i in sel.chosen]
    inertias = [g for g in groups if chosen[g[0]].kind == "point_inertia"]
    out = []
    def centre(group):
        return weighted_centre([chosen[k] for k in group], np.asarray(sel.values)[group])

    for gm in (g for g in groups if chosen[g[0]].kind == "point_mass"):
        c = centre(gm)
        near = [(float(np.linalg.norm(centre(gj) - c)), gj) for gj in inertias]
        near = [t for t in near if t[0] <= reach]
        if near:
            gj = min(near, key=lambda t: t[0])[1]
            out.append(([sel.chosen[k] for k in gm], [sel.chosen[k] for k in gj], c))
    return out


def _settle(res, p, others, home, centre, values, bounds, steps):
    """(fit, body) of the ``others`` candidates and a body at ``centre`` from magnitudes ``values``
    (others', m, J), its radius iterated to a fixed point; None where the fit fails."""
    fit = body = None
    for _ in range(RADIUS_ITERATIONS):
        radius = np.sqrt(values[-1] / values[-2])
        body = _body(home, centre, radius)
        fit = estimate(res, p, others + list(body), values, steps, bounds)
        if fit.state is None or not (fit.values[-2] > 0 and fit.values[-1] > 0):
            return None
        values = fit.values
        if abs(np.sqrt(values[-1] / values[-2]) / radius - 1.0) <= RADIUS_TOL:
            break
    return fit, body


def _fit_body(res, candidates, sel, others, home, centre, m: float, J: float, step: float, bounds, newton_steps):
    """(fit, body candidates) of ``others`` (candidate indices) and a body starting at ``centre``
    with (m, J): radius settled, centre placed by a pattern search from ``step`` down to ``step`` / 8
    (the shares' centre is only as good as the mesh they were found on, and a part beside a steep
    slope of a mode shape is felt millimetres away), radius settled again; or None."""
    pos = {i: k for k, i in enumerate(sel.chosen)}
    rest = [candidates[i] for i in others]
    out = _settle(res, sel.p, rest, home, centre, np.r_[[sel.values[pos[i]] for i in others], m, J], bounds,
                  newton_steps)
    if out is None:
        return None
    radius = np.sqrt(out[0].values[-1] / out[0].values[-2])
    xy, quick = pattern_search(res, rest, centre[:2], lambda xy: list(_body(home, np.r_[xy, 0.0], radius)), out[0],
                               step, 4, bounds)
    centre = np.r_[xy, 0.0]
    return _settle(res, quick.p, rest, home, centre, quick.values, bounds, newton_steps)


def as_bodies(res, candidates: list, sel, groups, reach: float, bounds=None, newton_steps: int = 8,
              alpha: float = ALPHA):
    """``sel`` with each group of chosen point masses (``groups``: lists of positions in
    ``sel.chosen`` reported as one effect) and the nearest group of chosen point inertias within
    ``reach`` [m] refitted as one body (module doc), where that lowers the criterion. Body
    candidates are appended to ``candidates``; ``sel`` is updated in place."""
    pen = penalty(res.n_rows, len(candidates), alpha)
    nodes = [x for x in candidates if x.kind == "point_mass" and "radius" not in x.data]
    for masses, inertias, c in _pairs(candidates, sel, groups, reach):
        if not set(masses + inertias) <= set(sel.chosen):  # an inertia already taken by another body
            continue
        pos = {i: k for k, i in enumerate(sel.chosen)}
        m, J = (float(sum(sel.values[pos[i]] for i in g)) for g in (masses, inertias))
        if not (m > 0 and J > 0) or not nodes:
            continue
        home = min(nodes, key=lambda x: np.hypot(x.at[0] - c[0], x.at[1] - c[1]))
        others = [i for i in sel.chosen if i not in masses and i not in inertias]
        centre = np.r_[c, 0.0]  # on the board's mid-plane
        out = _fit_body(res, candidates, sel, others, home, centre, m, J, reach / 10.0, bounds, newton_steps)
        if out is None or not out[0].chi2 + (len(others) + 2) * pen < sel.criterion[-1]:
            continue
        candidates.extend(out[1])
        adopt(sel, others + [len(candidates) - 2, len(candidates) - 1], out[0], pen)
    return sel
