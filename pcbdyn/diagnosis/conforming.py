"""The last stage of a diagnosis that found stiffeners: the structure meshed along their lines.

A stiffener the search finds is a beam embedded in the cells its line crosses (:mod:`.stiffener`).
Inside a coarse cell its rotations are the shell's, interpolated between the cell's nodes, so it
acts on the board as a rib smeared over the cell's width would: the search's criterion then places
it off its line (a bar glued at y = 112 mm found at 111.3 mm) and the error after stays above the
noise (0.6 %). Meshed along its line, the rib lies on a row of nodes, as it does on any finer
mesh: it is the same effect on every mesh, so it is carried onto the finer meshes that measure the
mesh correction, and chi^2 points at its line. This stage meshes the structure along the lines
found (``structure.following``, :mod:`pcbdyn.domain`), measures the mesh correction there with
every effect found carried, refits the declared parameters and all the effects' magnitudes, and
moves each line across to the vertex of a parabola through chi^2 at three places (each place a
mesh of its own). The fits are the one fitting engine's (:func:`.fitting.estimate`, the thesis'
bounded Gauss-Newton of ch. 4); only the model under them changes. The glued bar of
``tests/diagnosis/test_compound.py``: found at 112.09 mm for 112, 0.11 % after (0.61 % embedded);
on OpenSees' data (``ho_al_bar``) at 69.7 mm for 70, 0.28 % after (0.69 %), for 8-11 s more.
"""

from __future__ import annotations

import numpy as np

from ..domain import StructureError
from ..problems.models import StructureModels
from .catalogue import kind, place
from .fitting import Fit, estimate
from .layout import from_structure
from .residual import ModalResidual
from .stiffener import line_axis

#: [element sizes] the spacing of the three places of a stiffener's line whose chi^2 the parabola
#: goes through (the search leaves a line within a quarter element of its best embedded place, and
#: that place within about one element of the rib)
WALK = 0.25
#: most walks of one line (each a parabola through three places; a line found on the candidates'
#: grid, an element apart, lies up to half an element from the rib)
WALKS = 3
#: [element sizes] a line walked further than this has the mesh correction measured again where it
#: went (a shorter walk changes it little: the bar of ``ho_al_bar`` walked 0.45 mm and left 0.279 %
#: after with the correction measured again, 0.272 % without, for 4 s more)
REMEASURE = 0.25
#: Gauss-Newton steps of each fit of this stage (they start from the search's values)
STEPS = 8


def stiffeners(cands, sel) -> list:
    """Positions in ``sel.chosen`` of the stiffeners found."""
    return [j for j, i in enumerate(sel.chosen) if cands[i].kind == "stiffener"]


def remeshed(structure, configs, names, h: float, observations, chosen: list) -> tuple:
    """(models, residual, ``chosen`` placed on the new mesh) of ``structure`` meshed along the
    lines of the stiffeners among ``chosen`` (the observations re-read on it, their noise kept)."""
    lines = [np.asarray(c.geometry["path"], float) for c in chosen if c.kind == "stiffener"]
    models = StructureModels(structure.following(lines), configs, names, mesh_size=h, shared_mesh=True)
    obs = [ob.read_on(pm.model) for ob, pm in zip(observations, models.models)]
    layout = from_structure(models.models[0])
    return models, ModalResidual.of_models(models, obs), [place(layout, c) for c in chosen]


def moved(chosen: list, j: int, offset: float) -> list:
    """``chosen`` with the stiffener at ``j`` moved across its line by ``offset`` [m]."""
    path = np.asarray(chosen[j].geometry["path"], float)[[0, -1]]
    shift = np.zeros(2)
    shift[line_axis(path)] = offset
    out = list(chosen)
    out[j] = kind("stiffener").along(chosen[j], path + shift)
    return out


def fit_at(structure, configs, names, h, observations, chosen, p, values, bounds) -> tuple:
    """(models, residual, placed effects, :class:`.fitting.Fit`) on the mesh along ``chosen``'s lines."""
    models, res, placed = remeshed(structure, configs, names, h, observations, chosen)
    return models, res, placed, estimate(res, p, placed, values, STEPS, bounds)


def _trial(_, chosen, shared) -> Fit:
    """One place of the walk (a job): the fit's chi^2, parameters and magnitudes (no state; chi^2
    infinite where the structure cannot be meshed along the lines there)."""
    structure, configs, names, h, observations, p, values, bounds = shared
    try:
        fit = fit_at(structure, configs, names, h, observations, chosen, p, values, bounds)[3]
    except StructureError:  # e.g. a line too close to a part's outline for the mesher
        return Fit(p, values, None, np.zeros((0, 0)), np.inf)
    return Fit(fit.p, fit.values, None, np.zeros((0, 0)), fit.chi2)


def vertex(offsets, chi2) -> float:
    """The offset of the least chi^2 on the parabola through three (offset, chi^2) points equally
    spaced (the best of them where the parabola opens down), kept between the outer two."""
    (a, b, c), d = chi2, offsets[2] - offsets[1]
    curve = a - 2.0 * b + c
    if not (curve > 0.0 and np.isfinite(curve)):
        return float(offsets[int(np.argmin(chi2))])
    return float(np.clip(offsets[1] + 0.5 * d * (a - c) / curve, offsets[0], offsets[2]))


def walk(structure, configs, names, h, observations, chosen, j, fit, bounds, runner) -> float:
    """The offset [m] across its line towards the least chi^2 of stiffener ``j`` of ``chosen``: the
    places WALK elements to either side fitted (as jobs of ``runner``) beside ``fit`` (the fit at
    its present place), and the vertex of the parabola through the three (:func:`vertex`)."""
    d = WALK * h
    shared = (structure, configs, names, h, observations, fit.p, fit.values, bounds)
    side = runner.map(_trial, [(moved(chosen, j, -d),), (moved(chosen, j, d),)], shared, "places of a stiffener")
    return vertex([-d, 0.0, d], [side[0].chi2, fit.chi2, side[1].chi2])
