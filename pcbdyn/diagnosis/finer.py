"""The model on meshes finer than its own, solved for the model-form estimate (:mod:`.model_form`):
each configuration twice, four times, ... as fine, and on the finest as a Kirchhoff plate too.

These solves are independent of each other and cost most of a diagnosis on a loaded board (a
finer mesh has four, sixteen times the DOF), so they are jobs, run where a :class:`.scan.Runner`
says (local processes, a Dask cluster, this process); each returns only the frequencies and the
shapes at the test points, which the pairing level to level needs (:func:`.model_form.pair`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fe.modal import solve_modes
from ..problems.error_budget import KIRCHHOFF_SHEAR
from .catalogue import add_effect, place
from .layout import from_structure
from .residual import reading

#: modes solved on a finer mesh beyond the highest paired on the model's own, so that a mode that
#: moves up a place or two as the mesh resolves it is still there to pair
SPARE_MODES = 6


@dataclass(frozen=True)
class Solved:
    """A finer mesh's modes: ``f`` [Hz] and the shapes at the test points ``U`` (points x modes;
    None without measured shapes)."""

    f: np.ndarray
    U: np.ndarray | None


def solve(runner, structure, p: dict, requests: list) -> list:
    """:class:`Solved` per request (name, mesh size [m], Kirchhoff, masses [(candidate, value)],
    modes, test points (xyz, directions) or None) of ``structure`` at parameters ``p``."""
    order = sorted(range(len(requests)), key=lambda k: requests[k][1])  # finest (slowest) first
    done = runner.map(_solve_one, [requests[k] for k in order], (structure, p), "finer-mesh solves")
    out = [None] * len(requests)
    for k, s in zip(order, done):
        out[k] = s
    return out


def _solve_one(_, name, h, kirchhoff, masses, n_modes, points, shared) -> Solved:
    """One request of :func:`solve` (a job)."""
    structure, p = shared
    built = structure.build(name, h, shared_mesh=True).with_parameters(p)
    if kirchhoff:
        built = built.with_shear_factor(KIRCHHOFF_SHEAR)
    model = built.model
    if masses:
        layout = from_structure(built)
        for c, v in masses:
            model = add_effect(model, place(layout, c), v)
    modes = solve_modes(model, n_modes=n_modes)
    if points is None:
        return Solved(modes.frequencies, None)
    return Solved(modes.frequencies, np.asarray(reading(model, *points) @ modes.shapes))
