"""Where a rib lies and what section it has, fitted on meshes that follow it (issue 37: a bar need
not span the board, nor run along x or y, and it carries its mass).

The search places a stiffener on one of the lines it tries (across the whole plate in a few
directions, :mod:`.stiffener`), embedded in the cells it crosses. A glued bar stops short of the
edges, runs at its own angle and has its own section; and embedded in coarse cells a rib is stiffer
than on a row of nodes (the cells' rotations are interpolated under it: on a 8 mm mesh a diagonal bar
raised the first frequencies by 3 %, chi^2 300000 at the bar's place against 5000 meshed along it).
So its two ends (four coordinates) and ln h (its mass per length is 12 rho EI / (E h^2),
:meth:`.stiffener._Stiffener.mass`) are fitted with the declared parameters (ln p) and every
magnitude by the one fitting engine's bounded Gauss-Newton (thesis ch. 4), each trial on the
structure meshed along the ribs (:func:`.conforming.remeshed`), where chi^2 is smooth in the ends
and sharp at the bar (a millimetre across it: x4). The geometry's columns are forward differences
(:data:`STEP`), each a re-mesh and re-solve run as a job of the :class:`.scan.Runner`; the others'
are every fit's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..domain import StructureError
from ..updating.gauss_newton import gauss_newton
from . import conforming
from .catalogue import kind
from .fitting import UPPER, Fit

#: [element sizes] the forward-difference step of an end coordinate (and, in ln h, of the height)
STEP = 0.125
#: Gauss-Newton steps (each 1 + 5 re-meshed solves per rib, and halvings)
STEPS = 6
#: [m] bounds of the section height (a foil to a deep frame member)
HEIGHT = (0.5e-3, 30e-3)
#: [element sizes] the shortest rib (shorter, an end pair collapses into a point effect)
MIN_LENGTH = 2.0


@dataclass
class Ribs:
    """What the fit ends on: the structure's ``models`` meshed along the ribs, the residual ``res``
    there, the effects ``placed`` on it (ribs at their fitted ends and sections), and the ``fit`` of
    (ln p, magnitudes)."""

    models: object
    res: object
    placed: list
    fit: Fit


def _with_geometry(chosen, ribs, g, h):
    """``chosen`` with rib ``ribs[n]`` along g[5n:5n+4] (x0, y0, x1, y1) [m] of section exp(g[5n+4]);
    None where a rib would be shorter than :data:`MIN_LENGTH` elements."""
    out = list(chosen)
    for n, k in enumerate(ribs):
        x0, y0, x1, y1, ln_h = g[5 * n:5 * n + 5]
        if np.hypot(x1 - x0, y1 - y0) < MIN_LENGTH * h:
            return None
        rib = replace(chosen[k], data={**chosen[k].data, "height": float(np.exp(ln_h))})
        out[k] = kind("stiffener").along(rib, np.array([[x0, y0], [x1, y1]]))
    return out


def _solve(base, observations, effects, p, values):
    """(models, residual, placed, state) of the structure meshed along ``effects``' ribs, or None
    where it cannot be meshed there (a line too close to a part's outline)."""
    try:
        models, res, placed = conforming.remeshed(*base, observations, effects)
        return models, res, placed, res.evaluate(p, placed, values)
    except (StructureError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None


def _difference(_, g, shared):
    """One forward difference (a job): the residual rows at geometry ``g`` (None: not meshed there)."""
    base, observations, chosen, ribs, h, p, values = shared
    effects = _with_geometry(chosen, ribs, g, h)
    out = None if effects is None else _solve(base, observations, effects, p, values)
    return None if out is None else out[3].r


def fit_ribs(structure, configs, names, h: float, observations, chosen: list, p, values, bounds, runner,
             steps: int = STEPS) -> Ribs | None:
    """The stiffeners of ``chosen`` fitted at their ends and sections with the declared parameters
    ``p`` and all magnitudes ``values`` (module doc); None where ``chosen`` has no stiffener or the
    structure cannot be meshed along them."""
    ribs = [k for k, c in enumerate(chosen) if c.kind == "stiffener"]
    if not ribs:
        return None
    base = (structure, configs, names, h)
    p = np.asarray(p, float)
    npar, ne = p.size, len(chosen)
    spec = kind("stiffener")
    g0 = np.concatenate([np.r_[np.asarray(chosen[k].geometry["path"], float)[[0, -1]].ravel(),
                               np.log(chosen[k].data.get("height", spec.section.h))] for k in ribs])
    lo_xy = np.min([np.asarray(c.geometry["path"], float).min(axis=0) for c in (chosen[k] for k in ribs)], axis=0)
    hi_xy = np.max([np.asarray(c.geometry["path"], float).max(axis=0) for c in (chosen[k] for k in ribs)], axis=0)
    layout_lo, layout_hi = structure_extent(structure, lo_xy, hi_xy)
    v_lo = np.array([c.spec.lower for c in chosen], float)
    v_hi = UPPER * np.array([c.spec.scale for c in chosen], float)
    lo_p, hi_p = bounds if bounds is not None else (np.zeros(npar), np.full(npar, np.inf))
    lo_p = np.maximum(lo_p, 1e-6 * np.abs(p))
    with np.errstate(divide="ignore"):
        lower = np.r_[np.log(lo_p), v_lo, np.tile(np.r_[layout_lo, layout_lo, np.log(HEIGHT[0])], len(ribs))]
        upper = np.r_[np.log(hi_p), v_hi, np.tile(np.r_[layout_hi, layout_hi, np.log(HEIGHT[1])], len(ribs))]
    scale = np.r_[np.ones(npar), [c.spec.scale for c in chosen], np.tile([h, h, h, h, 1.0], len(ribs))]
    step = np.tile(np.r_[np.full(4, STEP * h), STEP], len(ribs))
    kept: dict = {}

    def evaluate(y):
        effects = _with_geometry(chosen, ribs, y[npar + ne:], h)
        out = None if effects is None else _solve(base, observations, effects, np.exp(y[:npar]), y[npar:npar + ne])
        if out is None:
            return None
        st = out[3]
        kept[id(st)] = (y.copy(), out)
        return st

    def jacobian(st):
        y, (_, res, placed, _) = kept[id(st)]
        g = y[npar + ne:]
        jobs = [(g + step[j] * np.eye(step.size)[j],) for j in range(step.size)]
        shared = (base, observations, chosen, ribs, h, np.exp(y[:npar]), y[npar:npar + ne])
        rows = runner.map(_difference, jobs, shared, "re-meshed trials of the ribs' ends")
        fd = np.column_stack([np.zeros(st.r.size) if r is None or r.size != st.r.size else -(r - st.r) / step[j]
                              for j, r in enumerate(rows)])
        cols = [res.param_columns(st)] if npar else []
        return np.hstack(cols + [res.effect_columns(st, placed), fd])

    y0 = np.r_[np.log(p), np.clip(np.asarray(values, float), v_lo, v_hi), g0]
    gn = gauss_newton(evaluate, jacobian, y0, lower, upper, scale, steps,
                      lambda y: np.r_[1e-4 * np.ones(npar), 1e-4 * np.maximum(np.abs(y[npar:npar + ne]),
                                                                               scale[npar:npar + ne]), 0.1 * step])
    if gn.state is None:
        return None
    y, (models, res, placed, st) = kept[id(gn.state)]
    n = npar + ne
    return Ribs(models, res, placed, Fit(np.exp(y[:npar]), y[npar:n], st, gn.cov[:n, :n]))


def structure_extent(structure, lo, hi) -> tuple:
    """(lower, upper) corners [m] the ribs' ends may take: the structure's outline's box where it has
    one (a board), else the box of the ribs as found."""
    outline = getattr(structure, "outline", None)
    if outline is None:
        return np.asarray(lo, float), np.asarray(hi, float)
    v = np.asarray(outline.vertices, float)
    return v.min(axis=0), v.max(axis=0)
