"""The last stage of a diagnosis that found stiffeners: the structure meshed along their lines.

A stiffener the search finds is a beam embedded in the cells its line crosses (:mod:`.stiffener`).
Inside a coarse cell its rotations are the shell's, interpolated between the cell's nodes, so it
acts on the board as a rib smeared over the cell's width would: the search's criterion then places
it off its line (a bar glued at y = 112 mm found at 111.3 mm) and the error after stays above the
noise (0.6 %). Meshed along its line, the rib lies on a row of nodes, as it does on any finer
mesh: it is the same effect on every mesh, so it is carried onto the finer meshes that measure the
mesh correction, and chi^2 points at its line. This stage meshes the structure along the lines
found (``structure.following``, :mod:`pcbdyn.domain`), measures the mesh correction there with
every effect found carried and refits the declared parameters and all the effects' magnitudes;
:mod:`.geometry_fit` then fits the ribs' ends and sections on meshes along them. The fits are the
one fitting engine's (:func:`.fitting.estimate`, the thesis' bounded Gauss-Newton of ch. 4); only
the model under them changes.
"""

from __future__ import annotations

import numpy as np

from ..problems.models import StructureModels
from .catalogue import place
from .layout import from_structure
from .residual import ModalResidual

#: [element sizes] a rib moved further than this by its fit has the mesh correction measured again
#: where it went (a shorter move changes it little: the bar of ``ho_al_bar`` moved 0.45 mm and left
#: 0.279 % after with the correction measured again, 0.272 % without, for 4 s more)
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
