"""How much a structure model's frequencies owe to its mesh: the change of each mode from the model's
mesh h to one twice as fine, at given parameter values.

A value fitted on mesh h absorbs the mesh's discretisation error (the shells are too stiff on a coarse
mesh, so a fitted equivalent thickness comes out low); predicting another board on a mesh of the same
density repeats that error, so the two largely cancel, but the fitted value is only known to within
what the mesh does. The change h -> h/2 is taken as the standard deviation of that error, per mode
(the converged value of an O(h^2) element lies 4/3 of a step away; part edges and the shells' shear
layer at free edges converge more slowly): a calibration adds it to its covariance as a systematic
error (:func:`pcbdyn.problems.calibration.systematic_shift`).
"""

from __future__ import annotations

import numpy as np

from ..correlation.mac import mac
from ..fe.modal import solve_modes
from ..fe.probe import model_probe
from .models import parameter_values


def mesh_step(problem, config, structure: int, p, n_modes: int) -> np.ndarray:
    """|f(h/2) - f(h)| / f(h) of the first ``n_modes`` elastic modes of configuration ``config`` of
    structure ``structure`` of ``problem`` (:class:`~.problem.UpdateProblem`) at parameter values
    ``p``; the finer model's modes are paired with the model's by MAC on the model's nodes."""
    sysm = problem.system(config, structure)
    s = problem.structures[structure]
    coarse = sysm.at(p)
    fine = s.build(config, (problem.mesh_size or s.mesh_size) / 2.0)
    fine = fine.with_parameters(parameter_values(fine, problem.names, p))
    mc = solve_modes(coarse.model, n_modes=n_modes)
    mf = solve_modes(fine.model, n_modes=n_modes + 4)
    U = np.asarray(model_probe(fine.model, coarse.model.nodes, (0.0, 0.0, 1.0), tol=0.02).P @ mf.shapes)
    k = mac(mc.shapes[2::6], U).argmax(axis=1)
    return np.abs(mf.frequencies[k] - mc.frequencies) / mc.frequencies


def measured_mesh_steps(problem, items, states, p) -> list:
    """Per test configuration (in order of ``states``, the correlation states of the tests of ``items``
    at ``p``): the mesh step (:func:`mesh_step`) of the model mode each measured mode pairs with (0
    for an unpaired one)."""
    out, n = [], 0
    for k, it in enumerate(items):
        for c, m in it.tests:
            pairs = states[n]["pairs"]
            n += 1
            step = mesh_step(problem, c, k, p, max(q["model_mode"] for q in pairs))
            u = np.zeros(m.frequencies.size)
            for q in pairs:
                u[q["test_mode"] - 1] = step[q["model_mode"] - 1]
            out.append(u)
    return out
