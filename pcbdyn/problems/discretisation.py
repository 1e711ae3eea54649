"""How much a structure model's frequencies (and shapes) owe to its mesh: the change of each mode from the model's
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


def model_errors(problem, tests, p, states) -> tuple:
    """What the mesh does to each measured mode at parameter values ``p``, per test configuration of
    ``tests`` [(structure index, configuration, Modes)] whose correlation states ``states`` pair them:
    (frequency errors [%], signed: f(h) / f(h/2) - 1 times 4/3, the Richardson estimate of the error of an
    O(h^2) element at h; shape errors: None without shapes, else (relative size: the rms of the change of
    the model's shape at the test points from h/2 to h, relative to its rms, times 4/3, per measured mode;
    the change itself, times 4/3, and the model's shape at h, both (n_meas, n_modes))). Zero for an
    unpaired mode. The two meshes' modes pair by MAC at the test points (on the model's nodes, out of
    plane, without shapes)."""
    freq, shape = [], []
    for (k, config, m), state in zip(tests, states):
        s = problem.structures[k]
        coarse = problem.system(config, k).at(p)
        fine = s.build(config, (problem.mesh_size or s.mesh_size) / 2.0)
        fine = fine.with_parameters(parameter_values(fine, problem.names, p))
        n = max([q["model_mode"] for q in state["pairs"]], default=0)
        e_f, e_s = np.zeros(m.frequencies.size), np.zeros(m.frequencies.size)
        change = None if m.shapes is None else np.zeros(m.shapes.shape)
        model = None if m.shapes is None else np.zeros(m.shapes.shape)
        if n:
            mc = solve_modes(coarse.model, n_modes=n)
            mf = solve_modes(fine.model, n_modes=n + 4)
            at = (m.xyz, m.directions) if m.shapes is not None else (coarse.model.nodes, (0.0, 0.0, 1.0))
            Uc = np.asarray(model_probe(coarse.model, *at, tol=0.02).P @ mc.shapes)
            Uf = np.asarray(model_probe(fine.model, *at, tol=0.02).P @ mf.shapes)
            partner = mac(Uc, Uf).argmax(axis=1)
            for q in state["pairs"]:
                j, i = q["model_mode"] - 1, q["test_mode"] - 1
                uc, uf = Uc[:, j], Uf[:, partner[j]]
                e_f[i] = 400.0 / 3.0 * (mc.frequencies[j] / mf.frequencies[partner[j]] - 1.0)
                diff = 4.0 / 3.0 * (uc - (uf @ uc) / (uf @ uf) * uf)
                e_s[i] = np.linalg.norm(diff) / np.linalg.norm(uc)
                if change is not None:
                    change[:, i], model[:, i] = diff, uc
        freq.append(e_f)
        shape.append(None if change is None else (e_s, change, model))
    return freq, shape
