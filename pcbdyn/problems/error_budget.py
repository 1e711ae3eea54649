"""The error budget between a structure model and a test: what the measurement noise, the model's mesh
and its plate theory leave between them, each with one rule, which diagnose, calibrate and wedgelock
all use (issue 37).

- Noise: a level stated as uniform bounds of +-p % (thesis eqs. 5.72-5.73) is a standard deviation of
  p / sqrt(3) % (:func:`noise_sigma`).
- Mesh: an O(h^2) element's frequency goes as f(h) = f0 + c h^2, so from the model's mesh h and one
  twice as fine, f0 = f(h/2) + (f(h/2) - f(h)) / 3 (Richardson) and the model's own error is 4/3 of
  the step (:func:`richardson`). A value fitted on mesh h absorbs that error (the shells are too stiff
  on a coarse mesh, so a fitted equivalent thickness comes out low); predicting another board on a mesh
  of the same density repeats it, so the two largely cancel, but the fitted value is only known to
  within what the mesh does: a calibration adds it to its covariance as a systematic error
  (:func:`pcbdyn.problems.calibration.systematic_shift`), a wedge-lock fit to each mode's tolerance,
  and a diagnosis corrects its frequencies to f0 and keeps a third of the step as uncertainty (part
  edges and the shells' shear layer at free edges converge more slowly than h^2).
- What the noise explains: chi^2 of a fit in noise units against its degrees of freedom (the
  chi-square test of thesis section 5.2.3, :func:`noise_probability`, :func:`noise_explains`), and the
  variance per row a fit leaves, never below the stated noise's (:func:`variance_left`): the unit in
  which a larger noise or a model error is weighed.
- Plate theory: the gap from the declared Mindlin shells to the Kirchhoff limit, the same model with
  its transverse shear :data:`KIRCHHOFF_SHEAR` times stiffer (:mod:`pcbdyn.diagnosis.model_form`).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2 as chi2_dist

from ..correlation.mac import mac
from ..fe.modal import solve_modes
from ..fe.probe import model_probe
from .models import parameter_values


#: the factor on the shells' transverse shear (``with_shear_factor`` of a structure's model) of the
#: Kirchhoff limit: a shear this much stiffer is a Kirchhoff plate to within 0.1 % of the gap
KIRCHHOFF_SHEAR = 1000.0


def noise_sigma(bound_pct) -> float | np.ndarray:
    """The relative standard deviation of noise stated as uniform bounds of +-``bound_pct`` %."""
    return np.asarray(bound_pct, float) / 100.0 / np.sqrt(3.0)


def noise_probability(chi2: float, dof: int) -> float:
    """The probability that noise alone gives at least ``chi2`` (in noise units) over ``dof`` >= 1
    degrees of freedom."""
    return float(chi2_dist.sf(chi2, dof))


def noise_explains(chi2: float, dof: int, alpha: float) -> bool:
    """Whether noise alone gives ``chi2`` over ``dof`` degrees of freedom (at least 1) with probability
    above ``alpha`` (the chi-square test of thesis section 5.2.3)."""
    return noise_probability(chi2, max(dof, 1)) > alpha


def variance_left(chi2: float, n: int, k: int) -> float:
    """The variance per row that a fit of ``k`` unknowns to ``n`` rows leaves with ``chi2``, at least the
    stated noise's (1)."""
    return max(chi2 / max(n - k, 1), 1.0)


def richardson(f_coarse, f_fine) -> tuple:
    """(converged frequency f0, the coarse mesh's error f(h) - f0 (positive where it is too stiff), what
    is left uncertain once corrected: a third of the step) from the frequencies on a mesh h and one twice
    as fine."""
    f_coarse, f_fine = np.asarray(f_coarse, float), np.asarray(f_fine, float)
    step = f_fine - f_coarse
    return f_fine + step / 3.0, -4.0 / 3.0 * step, np.abs(step) / 3.0


def mesh_step(problem, config, structure: int, p, n_modes: int) -> np.ndarray:
    """The relative error |f(h) - f0| / f(h) (:func:`richardson`) of the first ``n_modes`` elastic
    modes of configuration ``config`` of structure ``structure`` of ``problem``
    (:class:`~.problem.UpdateProblem`) at parameter values ``p``, from a mesh twice as fine; the finer
    model's modes are paired with the model's by MAC on the model's nodes."""
    sysm = problem.system(config, structure)
    s = problem.structures[structure]
    coarse = sysm.at(p)
    fine = s.build(config, (problem.mesh_size or s.mesh_size) / 2.0)
    fine = fine.with_parameters(parameter_values(fine, problem.names, p))
    mc = solve_modes(coarse.model, n_modes=n_modes)
    mf = solve_modes(fine.model, n_modes=n_modes + 4)
    U = np.asarray(model_probe(fine.model, coarse.model.nodes, (0.0, 0.0, 1.0), tol=0.02).P @ mf.shapes)
    k = mac(mc.shapes[2::6], U).argmax(axis=1)
    return np.abs(richardson(mc.frequencies, mf.frequencies[k])[1]) / mc.frequencies


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
    (frequency errors [%], signed: :func:`richardson`'s error at h relative to f(h/2); shape errors: None without shapes, else (relative size: the rms of the change of
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
                e_f[i] = 100.0 * richardson(mc.frequencies[j], mf.frequencies[partner[j]])[1] / mf.frequencies[partner[j]]
                diff = 4.0 / 3.0 * (uc - (uf @ uc) / (uf @ uf) * uf)
                e_s[i] = np.linalg.norm(diff) / np.linalg.norm(uc)
                if change is not None:
                    change[:, i], model[:, i] = diff, uc
        freq.append(e_f)
        shape.append(None if change is None else (e_s, change, model))
    return freq, shape
