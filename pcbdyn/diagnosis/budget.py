"""The error budget of a diagnosis' observations (issue 7, step 2; the rules are
:mod:`pcbdyn.problems.error_budget`'s): the measurement noise, stated or estimated from the shapes,
and the model's mesh correction and plate-theory gap measured on meshes finer than its own
(:mod:`.finer`), again with the effects found carried onto them (:func:`with_carried`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..fe.modal import solve_modes
from ..problems.error_budget import noise_sigma
from ..problems.models import parameter_values
from . import finer
from .model_form import discretisation, kirchhoff_shift
from .residual import Observation, reading

#: kinds whose effects :func:`with_carried` carries onto the finer meshes
MASS_KINDS = ("point_mass", "point_inertia", "line_mass", "region_mass")


def carried_by_the_stage(candidate) -> bool:
    """Whether the pipeline's carried stage puts an effect found onto the finer meshes
    (:func:`with_carried`): a mass (:data:`MASS_KINDS`, a rotary inertia on its disc of fixed size
    included) or a spring at a point between nodes (a support), the same effect on any mesh."""
    return candidate.kind in MASS_KINDS or candidate.between_nodes


def noise_sigmas(ob: Observation, freq_pct, shape_pct, basis_shapes):
    """Per-mode relative standard deviations of the frequencies and of a shape component
    (``basis_shapes``: the model's modes at the points, needed only where the shape noise is not stated)."""
    m = ob.f.size
    sf = np.full(m, noise_sigma(0.2 if freq_pct is None else freq_pct))
    if ob.shapes is None:
        return sf, None
    if shape_pct is not None:
        return sf, np.full(m, noise_sigma(shape_pct))
    n_pts = ob.shapes.shape[0]
    k = min(basis_shapes.shape[1], max(n_pts // 2, 1))
    Q, _ = np.linalg.qr(basis_shapes[:, :k])
    left = ob.shapes - Q @ (Q.T @ ob.shapes)
    rms = np.sqrt(np.mean(ob.shapes**2, axis=0))
    var = np.sum(left**2, axis=0) / max(n_pts - k, 1)
    return sf, np.maximum(np.sqrt(np.mean(var)) / rms, 1e-4)


def observations(tests, models) -> list:
    """An Observation per test [(configuration, Modes)], read on its configuration's built model, in unit
    sigmas until the noise is known (:func:`set_noise`)."""
    return [Observation(c, mm, np.ones(mm.n_modes)) if mm.shapes is None else
            Observation(c, mm, np.ones(mm.n_modes), reading(pm.model, mm.xyz, mm.directions), np.ones(mm.n_modes))
            for (c, mm), pm in zip(tests, models)]


def _requests(ob, cs, h, levels: int, carried=(), kirchhoff: bool = False) -> list:
    """The finer-mesh solves (:func:`.finer.solve`) of observation ``ob``, paired on the model's mesh
    as ``cs``: the meshes twice, four times, ... as fine as ``h`` (``levels`` of them), carrying
    ``carried`` (effects that are the same on any mesh: [(candidate, value)]), and with
    ``kirchhoff`` the finest again as a Kirchhoff plate."""
    points = None if ob.shapes is None else (ob.modes.xyz, ob.modes.directions)
    n_modes = int(cs.pairs.max()) + finer.SPARE_MODES
    out = [(ob.name, h / 2**j, False, tuple(carried), n_modes, points) for j in range(1, levels + 1)]
    return out + [(ob.name, h / 2**levels, True, tuple(carried), n_modes, points)] if kirchhoff else out


@dataclass
class Form:
    """What one observation's model form leaves: ``shift`` (the Kirchhoff limit's relative change
    per mode), ``measured`` (the measurement's frequency sigmas), ``plain`` (with the mesh's
    uncertainty, without the plate theory's gap) and ``resolved`` (the modes the mesh resolves)."""

    shift: np.ndarray
    measured: np.ndarray
    plain: np.ndarray = None
    resolved: list = None


def _correct(ob, cs, solved, form: Form):
    """(``ob`` with its frequency correction from ``solved`` (the modes on the finer meshes,
    :func:`.model_form.discretisation`) and its frequency sigmas (measurement, the correction's
    uncertainty and the plate theory's gap in quadrature), the shapes' relative error); sets
    ``form``'s ``plain`` and ``resolved``."""
    f_scale, df, ds, ok = discretisation(solved, ob, cs)
    form.plain, form.resolved = np.sqrt(form.measured**2 + df**2), ok.tolist()
    return replace(ob, f_scale=f_scale, sigma_f=np.sqrt(form.plain**2 + form.shift**2), noise_f=form.measured), ds


def set_noise(models, h, obs, state, freq_pct, shape_pct, levels: int, runner, support=()) -> list:
    """Each observation's discretisation correction of the model frequencies, and its sigmas:
    measurement noise, what remains of the discretisation error and the plate theory's gap, in
    quadrature (:mod:`.model_form`), from ``levels`` finer meshes (solved where ``runner`` says) at the
    declared parameters of ``state`` (the paired start), carrying its ``support`` springs ([(candidate,
    value)], :mod:`.support`). Returns (the observations with them, a :class:`Form` per observation)."""
    sigmas = []
    for ob, cs in zip(obs, state.configs):
        basis = None
        if ob.shapes is not None and shape_pct is None:  # rigid-body modes first: a free board's shapes hold them
            wide = solve_modes(cs.model, n_modes=ob.shapes.shape[0] // 2)
            basis = np.asarray(ob.read @ np.column_stack([wide.rigid_shapes, wide.shapes]))
        sigmas.append(noise_sigmas(ob, freq_pct, shape_pct, basis))
    requests = [r for ob, cs in zip(obs, state.configs) for r in _requests(ob, cs, h, levels, support, kirchhoff=True)]
    at = parameter_values(models.models[0], models.names, state.p)
    solved = iter(finer.solve(runner, models.structure, at, requests))
    forms, out = [], []
    for ob, cs, (sf, ss) in zip(obs, state.configs, sigmas):
        meshes = [next(solved) for _ in range(levels)]
        forms.append(Form(kirchhoff_shift(meshes[-1], next(solved), ob, cs), sf))
        ob, ds = _correct(ob, cs, meshes, forms[-1])
        out.append(replace(ob, sigma_s=None if ss is None else np.sqrt(ss**2 + ds**2)))
    return out, forms


def with_carried(models, res, p, carried, forms, h, levels: int, runner, kirchhoff: bool = False):
    """The mesh correction measured again at the fitted parameters ``p`` on the model carrying the
    masses and supports found (``carried``: [(candidate, value)], of :data:`MASS_KINDS` or between
    nodes), on its own mesh and placed on the ``levels`` finer ones: a mass changes the shapes, and
    so what the mesh does to the frequencies, of the modes it sits on (a connector along an edge: a
    third less on the modes it localises). Masses only, and springs at a point between nodes (a
    support), as they are the same on any mesh; a stiffness effect found on the model's mesh is
    partly its discretisation, and is left out on both sides of the comparison (a stiffener on a
    mesh along its line is not: :func:`_on_lines`). ``kirchhoff``: the plate theory's gap measured
    again too, on the finest mesh (a rib makes modes of other shapes, whose gap differs: 0.61 %
    against 0.13 % on the fourth mode of a card with a bar across it).
    Returns ``res`` of the observations with their new ``f_scale`` and frequency sigmas; sets the ``forms``."""
    ref = res.evaluate(p, [c for c, _ in carried], [v for _, v in carried])
    requests = [r for ob, cs in zip(res.observations, ref.configs) for r in _requests(ob, cs, h, levels, carried, kirchhoff)]
    at = parameter_values(models.models[0], models.names, p)
    solved = iter(finer.solve(runner, models.structure, at, requests))
    obs = []
    for ob, cs, form in zip(res.observations, ref.configs, forms):
        meshes = [next(solved) for _ in range(levels)]
        if kirchhoff:
            form.shift = kirchhoff_shift(meshes[-1], next(solved), ob, cs)
        obs.append(_correct(ob, cs, meshes, form)[0])
    return res.on(obs)
