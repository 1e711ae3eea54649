"""Diagnosis of a board against modal tests (issue 7): update the declared parameters, decide
whether what remains is noise, and otherwise find, place and size the effects the model lacks.

1. One mesh for every configuration (:class:`pcbdyn.problems.StructureModels`, ``shared_mesh``), test modes paired by
   MAC, residual rows in units of noise (:mod:`.residual`). A free model's test mode of rigid-body
   shape that no elastic mode resembles shows a support it lacks: a spring to ground is placed and
   sized from it (:mod:`.support`) and held through the search.
2. Noise: the stated levels (uniform bounds as in thesis eqs. 5.72-5.73, so a standard deviation
   of p / sqrt(3)), or, for shapes without a stated level, the part of each measured shape that no
   combination of the model's modes can represent (a measured shape projected on the span of as
   many modes as half the points; what is left over is noise). Model discretisation: the paired
   frequencies are corrected to a converged mesh by Richardson extrapolation from the two
   coarsest meshes (the model's, twice, four times as fine) that resolve the mode (an O(h^2)
   element); what that leaves uncertain, and the shapes' change (4/3 of it), is added to the
   noise in quadrature, so that a coarse mesh is neither mistaken for an effect nor left in the
   error reported after. So is the plate theory's gap on the finest mesh (Mindlin against
   Kirchhoff: the board's transverse shear stiffness is a guess; :mod:`.model_form`).
3. The declared parameters alone are fitted; if chi^2 is within what noise gives (chi-square
   test, probability ``alpha``) the data lie in the range of the model (thesis section 5.2.3) and
   nothing is invented.
4. Otherwise the catalogue's candidates are searched (:func:`.select.search`), the effects'
   magnitudes estimated together with the declared parameters, each effect kept only if it
   also predicts data it was not fitted to; runs along the sides, stiffener lines and
   rectangular regions are walked to where they fit best (:func:`.select.refine`,
   :class:`LocalMoves`) and a mass with an inertia beside it refitted as one body
   (:mod:`.bodies`). The masses (and supports) found are then put on the finer meshes and the mesh
   correction measured again (:func:`_with_carried`: they change the shapes it depends on); where
   stiffeners were found, the structure is meshed along their lines first, every effect carried,
   and the lines walked there (:func:`_on_lines`, :mod:`.conforming`). Last, the plate
   theory's share is fitted with the effects found (:func:`.model_form.fit_plate_share`; kept
   only where significant).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace

import numpy as np
import shapely
from scipy.stats import chi2 as chi2_dist

from ..domain import StructureError
from ..fe.modal import solve_modes
from ..fe.probe import ProbeError, segment_parameter
from ..parallel import spare_cores
from ..problems.models import StructureModels, parameter_values
from .bodies import as_bodies
from .catalogue import KINDS, generate, kind, weighted_centre
from .layout import from_structure
from . import conforming, finer
from .model_form import MESH_LEVELS, discretisation, fit_plate_share, kirchhoff_shift
from .residual import ModalResidual, Observation, reading
from .fitting import estimate
from .scan import Runner
from .select import ALPHA, adopt, penalty, refine, search, without_vanished
from .support import supports
from .uncertainty import jackknife_cov, parts

#: kinds whose effects :func:`_with_carried` carries onto the finer meshes
MASS_KINDS = ("point_mass", "point_inertia", "line_mass")

#: where candidates go: sides cut into 16 pieces (every run of consecutive pieces is a candidate);
#: stiffener rows and columns every element (``path_spacing`` in element sizes)
CANDIDATE_OPTIONS = {"segments": 16, "path_spacing": 1.0}
#: ``quick`` (a first look): candidates on a grid half as fine, the refinement walking them to place
QUICK_CANDIDATE_OPTIONS = {"segments": 8, "path_spacing": 2.0}


def _options(kinds) -> set:
    return {o for name in (kinds or KINDS) for o in kind(name).options}

@dataclass
class Diagnosis:
    """The outcome: ``effects`` (JSON-ready dicts), ``noise_only``, ``message`` (plain words),
    correlation summaries ``before`` (model as given), ``parameters_only`` (declared parameters
    fitted) and ``after`` (with the effects), the declared parameter values and the test
    statistics; ``evidence``: {kind: (node xy (n, 2) [m], chi^2 a candidate there removes)} at the
    parameters-only state, the map of where the residual points."""

    effects: list
    noise_only: bool
    message: str
    before: dict
    parameters_only: dict
    after: dict
    parameters: dict
    statistics: dict
    evidence: dict = field(default_factory=dict)
    candidates: list = field(default_factory=list)


def _noise_sigmas(ob: Observation, freq_pct, shape_pct, basis_shapes):
    """Per-mode relative standard deviations of the frequencies and of a shape component
    (``basis_shapes``: the model's modes at the points, needed only where the shape noise is not stated)."""
    m = ob.f.size
    sf = np.full(m, (0.2 if freq_pct is None else freq_pct) / 100.0 / np.sqrt(3.0))
    if ob.shapes is None:
        return sf, None
    if shape_pct is not None:
        return sf, np.full(m, shape_pct / 100.0 / np.sqrt(3.0))
    n_pts = ob.shapes.shape[0]
    k = min(basis_shapes.shape[1], max(n_pts // 2, 1))
    Q, _ = np.linalg.qr(basis_shapes[:, :k])
    left = ob.shapes - Q @ (Q.T @ ob.shapes)
    rms = np.sqrt(np.mean(ob.shapes**2, axis=0))
    var = np.sum(left**2, axis=0) / max(n_pts - k, 1)
    return sf, np.maximum(np.sqrt(np.mean(var)) / rms, 1e-4)


def _observations(tests, models) -> list:
    """An Observation per test [(configuration, Modes)], read on its configuration's built model."""
    obs = []
    for (c, mm), pm in zip(tests, models):
        ob = Observation(c, mm, np.ones(mm.n_modes))
        if mm.shapes is not None:
            ob.read = reading(pm.model, mm.xyz, mm.directions)
            ob.sigma_s = np.ones(mm.n_modes)  # until the noise is known
        obs.append(ob)
    return obs


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
class _Form:
    """What one observation's model form leaves: ``shift`` (the Kirchhoff limit's relative change
    per mode), ``measured`` (the measurement's frequency sigmas), ``plain`` (with the mesh's
    uncertainty, without the plate theory's gap) and ``resolved`` (the modes the mesh resolves)."""

    shift: np.ndarray
    measured: np.ndarray
    plain: np.ndarray = None
    resolved: list = None


def _correct(ob, cs, solved, form: _Form):
    """Sets ``ob``'s frequency correction from ``solved`` (the modes on the finer meshes,
    :func:`.model_form.discretisation`) and its frequency sigmas (measurement, the correction's
    uncertainty and the plate theory's gap in quadrature), and ``form``'s ``plain`` and
    ``resolved``; returns the shapes' relative error."""
    ob.f_scale, df, ds, ok = discretisation(solved, ob, cs)
    form.plain, form.resolved = np.sqrt(form.measured**2 + df**2), ok.tolist()
    ob.sigma_f = np.sqrt(form.plain**2 + form.shift**2)
    return ds


def _set_noise(models, h, obs, state, freq_pct, shape_pct, levels: int, runner, support=()) -> list:
    """Each observation's discretisation correction of the model frequencies, and its sigmas:
    measurement noise, what remains of the discretisation error and the plate theory's gap, in
    quadrature (:mod:`.model_form`), from ``levels`` finer meshes (solved where ``runner`` says)
    that carry the ``support`` springs of ``state`` ([(candidate, value)], :mod:`.support`).
    Returns a :class:`_Form` per observation."""
    sigmas = []
    for ob, cs in zip(obs, state.configs):
        basis = None
        if ob.shapes is not None and shape_pct is None:  # rigid-body modes first: a free board's shapes hold them
            wide = solve_modes(cs.model, n_modes=ob.shapes.shape[0] // 2)
            basis = np.asarray(ob.read @ np.column_stack([wide.rigid_shapes, wide.shapes]))
        sigmas.append(_noise_sigmas(ob, freq_pct, shape_pct, basis))
    requests = [r for ob, cs in zip(obs, state.configs) for r in _requests(ob, cs, h, levels, support, kirchhoff=True)]
    p0 = parameter_values(models.models[0], models.names, models.p0)
    solved = iter(finer.solve(runner, models.structure, p0, requests))
    forms = []
    for ob, cs, (sf, ss) in zip(obs, state.configs, sigmas):
        meshes = [next(solved) for _ in range(levels)]
        forms.append(_Form(kirchhoff_shift(meshes[-1], next(solved), ob, cs), sf))
        ds = _correct(ob, cs, meshes, forms[-1])
        ob.sigma_s = None if ss is None else np.sqrt(ss**2 + ds**2)
    return forms


def _with_carried(models, res, p, carried, forms, h, levels: int, runner, kirchhoff: bool = False) -> None:
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
    Sets the observations' ``f_scale`` and frequency sigmas and the ``forms``."""
    ref = res.evaluate(p, [c for c, _ in carried], [v for _, v in carried])
    requests = [r for ob, cs in zip(res.observations, ref.configs) for r in _requests(ob, cs, h, levels, carried, kirchhoff)]
    at = parameter_values(models.models[0], models.names, p)
    solved = iter(finer.solve(runner, models.structure, at, requests))
    for ob, cs, form in zip(res.observations, ref.configs, forms):
        meshes = [next(solved) for _ in range(levels)]
        if kirchhoff:
            form.shift = kirchhoff_shift(meshes[-1], next(solved), ob, cs)
        _correct(ob, cs, meshes, form)


def _on_lines(models, res, cands, sel, forms, h, levels: int, runner, alpha, say):
    """(models, residual, candidates, selection) after :mod:`.conforming`'s stage, or None where the
    structure cannot be meshed along the lines found: parallel stiffeners fitted as shares of one
    rib (:func:`_linked`) made that rib (their summed EI on their weighted mean line), the structure
    meshed along the stiffeners, the mesh correction measured there with every effect found carried
    onto the finer meshes (a rib on a row of nodes is the same on any mesh) with the plate theory's
    gap, each line walked across to its least chi^2 (the correction measured again where a line
    went further than :data:`.conforming.REMEASURE`), and the declared parameters and magnitudes
    refitted. ``cands`` is returned with the chosen effects replaced by
    their places on the new mesh (same indices: the selection's penalty keeps its count)."""
    idx, chosen, values = list(sel.chosen), [cands[i] for i in sel.chosen], np.asarray(sel.values, float).copy()
    keep = []
    for g in _neighbours(chosen, MERGE_REACH * h):
        if len(g) > 1 and all(chosen[k].kind == "stiffener" for k in g):
            chosen[g[0]] = kind("stiffener").along(chosen[g[0]], _mean_path([chosen[k] for k in g], values[g]))
            values[g[0]] = values[g].sum()
            g = g[:1]
        keep += g
    keep.sort()
    idx, chosen, values = [idx[k] for k in keep], [chosen[k] for k in keep], values[keep]
    base = (models.structure, models.configs, models.names, h)
    say("meshing along the stiffeners found; the mesh correction with every effect found carried")
    try:
        models, res, placed = conforming.remeshed(*base, res.observations, chosen)
    except StructureError as exc:
        say(f"  not meshed along them ({exc}): the stiffeners stay embedded in the model's cells")
        return None
    _with_carried(models, res, sel.p, list(zip(placed, values)), forms, h, levels, runner, kirchhoff=True)
    fit = estimate(res, sel.p, placed, values, conforming.STEPS, models.bounds)
    for j, c in enumerate(chosen):
        if c.kind != "stiffener":
            continue
        moved = 0.0
        for _ in range(conforming.WALKS):
            say(f"walking {chosen[j].name} across its line")
            offset = conforming.walk(*base, res.observations, chosen, j, fit, models.bounds, runner)
            if not offset:
                break
            there = conforming.moved(chosen, j, offset)
            try:
                trial = conforming.fit_at(*base, res.observations, there, fit.p, fit.values, models.bounds)
            except StructureError:  # not meshed there: the line stays
                break
            if not trial[3].chi2 < fit.chi2:  # the parabola's vertex is no better: the line stays
                break
            (models, res, placed, fit), chosen, moved = trial, there, moved + offset
            if abs(offset) < conforming.WALK * h * (1.0 - 1e-9):  # an inner vertex: the walk has arrived
                break
        if abs(moved) > conforming.REMEASURE * h:
            say(f"  {chosen[j].name}: the mesh correction measured there")
            _with_carried(models, res, fit.p, list(zip(placed, fit.values)), forms, h, levels, runner, kirchhoff=True)
            fit = estimate(res, fit.p, placed, fit.values, conforming.STEPS, models.bounds)
    out = list(cands)
    for i, c in zip(idx, placed):
        out[i] = c
    return models, res, out, adopt(sel, idx, fit, penalty(res.n_rows, len(cands), alpha))


def _supports(res, p0, before, models, kinds, say) -> tuple:
    """(support springs [(candidate, value)], the state of ``res`` with them): the springs to ground
    that measured modes of rigid-body shape demand of a free model (:func:`.support.supports`; none
    where the kinds searched leave springs out)."""
    if "ground_spring" not in (kinds or KINDS):
        return [], before
    layout = from_structure(models.models[0])
    found, state = supports(res, p0, before, generate(layout, ["ground_spring"]), layout)
    if found:
        say("test modes of rigid-body shape: the model lacks a support; "
            + ", ".join(f"{c.name} ({v:.3g} N/m)" for c, v in found))
    return found, state


def _range_test(res, base, n_params, alpha) -> dict:
    """Chi-square test of the parameters-only residual and the ranks of A and [A b] at the noise
    level (thesis section 5.2.3: b outside the range of A is what the parameters cannot explain)."""
    dof = max(res.n_rows - n_params, 1)
    A = res.param_columns(base.state)
    level = np.sqrt(chi2_dist.isf(alpha, dof))
    return {"rows": res.n_rows, "dof": dof, "chi2_parameters_only": base.chi2,
            "p_value_noise": float(chi2_dist.sf(base.chi2, dof)), "alpha": alpha,
            "rank_A": int(np.sum(np.linalg.svd(A, compute_uv=False) > level)) if A.size else 0,
            "rank_Ab": int(np.sum(np.linalg.svd(np.column_stack([A, base.state.r]), compute_uv=False) > level))}


def diagnose(structure, tests, freq_noise_pct=None, shape_noise_pct=None, mesh_size=None, kinds=None,
             max_effects: int = 3, alpha: float = ALPHA, progress=None, workers: int | None = None,
             scheduler=None, quick: bool = False) -> Diagnosis:
    """Diagnose ``structure`` (a board, or any structure of :mod:`pcbdyn.domain`) against ``tests`` =
    [(configuration name or None, :class:`pcbdyn.testdata.Modes`)]. ``workers`` local processes (None:
    the cores; 1: this process) or the Dask cluster at ``scheduler`` run the independent solves of
    the finer meshes (:mod:`.finer`) and fits of the candidate scans (:mod:`.scan`); the results do
    not depend on where they ran. ``quick``: a first look that costs a fraction of the run: the
    mesh correction from one finer mesh (twice as fine) instead of :data:`.model_form.MESH_LEVELS`,
    the candidates on a grid half as fine (:data:`QUICK_CANDIDATE_OPTIONS`, the local search still
    walks them to place), one trial per kind in each scan instead of two, and the masses found not
    carried onto the finer meshes to measure the correction again. The configurations of each
    re-solve share the local cores (:func:`pcbdyn.parallel.spare_cores`)."""
    with spare_cores(workers):
        return _diagnose(structure, tests, freq_noise_pct, shape_noise_pct, mesh_size, kinds, max_effects, alpha,
                         progress, workers, scheduler, quick)


def _diagnose(structure, tests, freq_noise_pct, shape_noise_pct, mesh_size, kinds, max_effects, alpha, progress,
              workers, scheduler, quick) -> Diagnosis:
    say = progress or (lambda msg: None)
    runner = Runner(workers, scheduler, lambda msg: say(f"  {msg}"))
    h = mesh_size or structure.mesh_size
    say("building the models")
    models = StructureModels(structure, [c for c, _ in tests], mesh_size=h, shared_mesh=True)
    names, p0 = models.names, models.p0
    obs = _observations(tests, models.models)
    res = ModalResidual.of_models(models, obs)
    say("solving the model as given")
    before = res.evaluate(p0)
    unmatched = {ob.name or "base": (np.flatnonzero(~cs.matched) + 1).tolist() for ob, cs in zip(obs, before.configs)}
    support, shown, left, bounce = [], {}, unmatched, [np.zeros(ob.f.size, bool) for ob in obs]
    if any(unmatched.values()):  # modes the model has no partner for (MAC < 0.3): local modes of what it lacks
        support, paired = _supports(res, p0, before, models, kinds, say)
        bounce = [cs.matched & ~c0.matched for cs, c0 in zip(paired.configs, before.configs)]
        shown = {ob.name or "base": (np.flatnonzero(b) + 1).tolist() for ob, b in zip(obs, bounce)}
        left = {ob.name or "base": (np.flatnonzero(~cs.matched) + 1).tolist() for ob, cs in zip(obs, paired.configs)}
        if any(left.values()):
            say(f"test modes without a model partner, left out: {left}")
        obs = [ob.subset(cs.matched) for ob, cs in zip(obs, paired.configs)]
        bounce = [b[cs.matched] for b, cs in zip(bounce, paired.configs)]
        res = ModalResidual.of_models(models, obs)
        before = res.evaluate(p0)
    say("estimating the noise and the model's discretisation error")
    levels = 1 if quick else MESH_LEVELS
    say("  finer meshes: " + ", ".join(f"level {j} of {levels} ({1e3 * h / 2**j:.3g} mm)" for j in range(1, levels + 1)))
    seed = res.evaluate(p0, [c for c, _ in support], [v for _, v in support]) if support else before
    forms = _set_noise(models, h, obs, seed, freq_noise_pct, shape_noise_pct, levels, runner, support)
    before = res.evaluate(p0)
    say(f"fitting the {len(names)} declared parameter(s)" if names else "no declared parameters")
    # the declared parameters alone, on the modes they can pair (a support's bounce has no partner without it)
    plain = ModalResidual.of_models(models, [ob.subset(~b) for ob, b in zip(obs, bounce)]) if support else res
    base = estimate(plain, p0, [], [], 10, models.bounds)
    stats = {"quick": quick, "unpaired_test_modes": unmatched, "support_test_modes": shown, "chi2_before": before.chi2,
             **_range_test(plain, base, len(names), alpha),
             "mesh_correction_pct": [np.round(100 * (o.f_scale - 1.0), 4).tolist() for o in obs],
             "mesh_resolved": [f.resolved for f in forms],
             "plate_theory_pct": [np.round(100 * f.shift, 4).tolist() for f in forms],
             "sigma_f_pct": [np.round(100 * o.sigma_f, 4).tolist() for o in obs],
             "sigma_shape_pct": [None if o.sigma_s is None else np.round(100 * o.sigma_s, 4).tolist() for o in obs]}
    out = dict(before=before.summary(obs), parameters_only=(res.evaluate(base.p) if support else base.state).summary(obs),
               parameters={n: {"initial": float(a), "parameters_only": float(b)} for n, a, b in zip(names, p0, base.p)},
               statistics=stats)
    if stats["p_value_noise"] > alpha and not any(unmatched.values()):
        for n, v in zip(names, base.p):
            out["parameters"][n]["final"] = float(v)
        return Diagnosis([], True, "what remains after fitting the declared parameters is within the noise "
                         f"(chi^2 = {base.chi2:.1f} for {stats['dof']} degrees of freedom, p = "
                         f"{stats['p_value_noise']:.2f}): no effect is missing that the data can show",
                         after=out["parameters_only"], **out)
    say("generating the candidate effects")
    grid = QUICK_CANDIDATE_OPTIONS if quick else CANDIDATE_OPTIONS
    options = {k: v * h if k == "path_spacing" else v for k, v in grid.items() if k in _options(kinds)}
    layout = from_structure(models.models[0])
    cands = generate(layout, kinds, **options)
    say(f"searching {len(cands)} candidate effects")
    cands += [c for c, _ in support]
    held = list(range(len(cands) - len(support), len(cands)))
    start = base
    if held:
        say("fitting the support with the declared parameters")
        start = estimate(res, base.p, [cands[i] for i in held], [v for _, v in support], 10, models.bounds)
    sel = search(res, cands, p0, models.bounds, max_effects=max_effects, shortlist=1 if quick else 2, alpha=alpha,
                 base=start, runner=runner, held=held)
    if any(_movable(cands[i]) for i in sel.chosen):
        say("refining where the effects along the sides begin and end, where stiffeners run and what regions cover")
        sel = refine(res, cands, sel, LocalMoves(layout, cands, h), models.bounds, alpha=alpha, runner=runner)
    if {"point_mass", "point_inertia"} <= {cands[i].kind for i in sel.chosen}:
        say("fitting a part found as a mass with an inertia beside it as one body")
        sel = as_bodies(res, cands, sel, _neighbours([cands[i] for i in sel.chosen], MERGE_REACH * h),
                        MERGE_REACH * h, models.bounds, alpha=alpha)
    sel = without_vanished(res, cands, sel, models.bounds, alpha=alpha)
    carried = [(cands[i], v) for i, v in zip(sel.chosen, sel.values) if cands[i].kind in MASS_KINDS or cands[i].between_nodes]
    searched = cands  # the candidates on the model's own mesh (the evidence map is drawn on it)
    lined = None if quick or not conforming.stiffeners(cands, sel) else \
        _on_lines(models, res, cands, sel, forms, h, levels, runner, alpha, say)
    if lined is not None:
        models, res, cands, sel = lined
        obs = res.observations
    elif carried and not quick:
        say("measuring the mesh correction again with the masses (and supports) found on the finer meshes")
        _with_carried(models, res, sel.p, carried, forms, h, levels, runner)
        sel = adopt(sel, sel.chosen, estimate(res, sel.p, [cands[i] for i in sel.chosen], sel.values, 8, models.bounds),
                    penalty(res.n_rows, len(cands), alpha))
    if lined is not None or (carried and not quick):
        stats["mesh_resolved"] = [f.resolved for f in forms]
        stats["mesh_correction_pct"] = [np.round(100 * (o.f_scale - 1.0), 4).tolist() for o in obs]
        stats["plate_theory_pct"] = [np.round(100 * f.shift, 4).tolist() for f in forms]
    say("fitting the plate theory's share with the effects")
    sel, theta, theta_sigma = fit_plate_share(res, cands, sel, [f.shift for f in forms], [f.plain for f in forms],
                                              models.bounds, alpha=alpha)
    stats.update(plate_theory_share=theta, plate_theory_share_sigma=theta_sigma)
    stats.update(chi2_after=sel.chi2[-1], candidates=len(cands))
    for n, v in zip(names, sel.p):
        out["parameters"][n]["final"] = float(v)
    chosen = [cands[i] for i in sel.chosen]
    cov_jack = jackknife_cov(res, sel.state, chosen, np.array([c.spec.scale for c in chosen]))
    effects = [_merged(chosen, sel.values, sel.cov, cov_jack, g) for g in _neighbours(chosen, MERGE_REACH * h)]
    if effects:
        msg = f"{len(effects)} effect(s) the model lacks: " + "; ".join(
            f"{e['type']} ({e['parameter']}) at {e['at_mm']} mm" for e in effects)
    else:
        msg = ("the residual exceeds the noise but no candidate effect explains it beyond chance: "
               "nothing is reported (check the noise level, the pairing and the declared parameters)")
    if theta > 0.0:
        msg += (f"; the frequencies lie {100 * theta:.0f} +- {100 * theta_sigma:.0f} % of the way from the declared "
                "Mindlin shells to the Kirchhoff limit (statistics.plate_theory_share): the board's transverse shear "
                "is stiffer than declared (board.transverse_shear can be updated as a parameter)")
    if support:
        msg += (f"; test modes of rigid-body shape {shown} show a support the free model lacks, placed and sized "
                "from them (a spring to ground)")
    if any(left.values()):
        msg += f"; test modes with no model partner (MAC < 0.3), left out of the fit: {left}"
    return Diagnosis(effects, False, msg, after=sel.state.summary(obs), evidence=_evidence(plain, base.state, searched),
                     candidates=chosen, **out)


#: the name of a candidate over a run of pieces of a side: "<kind>@<side>[i]" or "[i-j]"
RUN = re.compile(r"^(?P<base>.+)\[(?P<i>\d+)(?:-(?P<j>\d+))?\]$")
#: the name of a stiffener row or column: "stiffener@y=<value>mm" or "stiffener@x=<value>mm"
LINE = re.compile(r"^(?P<base>.+@[xy])=(?P<v>[-0-9.e]+)mm$")


def _movable(cand) -> bool:
    """A candidate :class:`LocalMoves` can move (a run of pieces of a side, a stiffener line, a
    rectangular region, a point between nodes)."""
    return bool(RUN.match(cand.name) or LINE.match(cand.name) or _rectangle(cand) is not None or cand.between_nodes)


def _rectangle(cand):
    """(x0, y0, x1, y1) [m] of a region candidate whose polygon is an axis-aligned rectangle, else None."""
    if cand.kind != "region_stiffness" or np.shape(cand.geometry["polygon"])[1] != 2:
        return None
    poly = np.asarray(cand.geometry["polygon"], float)
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    on_box = np.all(np.isclose(poly[:, :1], [lo[0], hi[0]]).any(axis=1) & np.isclose(poly[:, 1:], [lo[1], hi[1]]).any(axis=1))
    return (*lo, *hi) if len(poly) == 4 and on_box else None


class LocalMoves:
    """neighbours(i) for :func:`.select.refine`: for a run of pieces of a side, the runs of the
    same kind and side that start and end at most one piece from its own; for a stiffener line,
    the lines half an element (:data:`LINE_STEP`) to either side; for a rectangular region, the
    rectangles with one side moved by one element (:data:`RECT_STEP`) in or out; for a point
    between nodes (a support, :mod:`.support`), the points a quarter element (:data:`POINT_STEP`)
    away along x and y.
    Lines, rectangles and points are made on demand and appended to ``cands`` (the first grid
    places an effect within a grid step; these walk it to where it is)."""

    def __init__(self, layout, cands: list, h: float):
        self.layout, self.cands, self.h = layout, cands, h
        plate = layout.xy[layout.shell_nodes()]
        self.lo, self.hi = plate.min(axis=0), plate.max(axis=0)
        self.index = {c.name: k for k, c in enumerate(cands)}
        self.runs: dict = {}
        for k, c in enumerate(cands):
            if m := RUN.match(c.name):
                self.runs.setdefault(m["base"], {})[(int(m["i"]), int(m["j"] or m["i"]))] = k

    def _add(self, made) -> list:
        out = []
        for c in made:
            if c.name not in self.index:
                self.index[c.name] = len(self.cands)
                self.cands.append(c)
            out.append(self.index[c.name])
        return out

    def __call__(self, k) -> list:
        c = self.cands[k]
        if m := RUN.match(c.name):
            i, j = int(m["i"]), int(m["j"] or m["i"])
            side = self.runs[m["base"]]
            return [side[(a, b)] for a in (i - 1, i, i + 1) for b in (j - 1, j, j + 1)
                    if (a, b) != (i, j) and (a, b) in side]
        if LINE.match(c.name):
            return self._add(kind("stiffener").parallel(self.layout, c, LINE_STEP * self.h * np.array([-1.0, 1.0])))
        if c.between_nodes:
            step, made = POINT_STEP * self.h, []
            for d in ((step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)):
                try:
                    made.append(c.spec.place(self.layout, replace(c, at=(c.at[0] + d[0], c.at[1] + d[1]))))
                except ProbeError:  # off the board
                    continue
            return self._add(made)
        if (box := _rectangle(c)) is not None:
            lo, hi, step, made = self.lo, self.hi, RECT_STEP * self.h, []
            for side in range(4):
                for d in (-step, step):
                    b = np.array(box)
                    b[side] = np.clip(b[side] + d, lo[side % 2], hi[side % 2])
                    if b[2] - b[0] >= step and b[3] - b[1] >= step and not np.allclose(b, box):
                        made.append(kind("region_stiffness").rectangle(self.layout, *b))
            return self._add([r for r in made if r is not None])
        return []


#: [element sizes] how far a stiffener line moves in one step of the local search (:func:`_on_lines`
#: then walks it to a fraction of this on meshes along it; twice as far in a step as a point moves:
#: the bar of ``ho_al_bar``, found as two lines, took 22 s of local search in quarter steps, 13 s in
#: halves)
LINE_STEP = 0.5
#: [element sizes] how far a point between nodes moves in one step of the local search
POINT_STEP = 0.25
#: [element sizes] how far a side of a rectangular region moves in one step of the local search
RECT_STEP = 1.0


#: kinds that act at one node: an effect between nodes is shared by its neighbours
POINT_KINDS = ("point_mass", "point_inertia", "ground_spring")
#: [element sizes] how far apart shares of one effect may be found (an unstructured mesh puts the
#: nodes around a point up to about two elements apart)
MERGE_REACH = 2.6


def _linked(a, b, reach: float) -> bool:
    """Two chosen effects that are one: point effects of one kind within ``reach`` [m] (a mass or a
    spring between nodes is fitted as shares on the nodes around it), or a point mass within
    ``reach`` of a line mass (a mass spread over part of an edge is fitted as a line plus points),
    line masses whose segments overlap or lie within ``reach``, parallel stiffeners within
    ``reach`` (a rib between two lines is fitted as shares on both), or overlapping rectangular
    regions (a region between two is fitted as both)."""
    if a.kind == b.kind and a.kind in POINT_KINDS:
        return math.dist(a.at, b.at) <= reach
    if a.kind == b.kind == "region_stiffness" and None not in (ra := _rectangle(a), rb := _rectangle(b)):
        return min(ra[2], rb[2]) > max(ra[0], rb[0]) and min(ra[3], rb[3]) > max(ra[1], rb[1])  # they overlap
    if a.kind == b.kind == "stiffener":
        da, db = (np.diff(np.asarray(c.geometry["path"], float)[[0, -1]], axis=0)[0] for c in (a, b))
        parallel = abs(da[0] * db[1] - da[1] * db[0]) <= 1e-6 * np.linalg.norm(da) * np.linalg.norm(db)
        return parallel and _segment_gap(a.geometry["path"], b.geometry["path"]) <= reach
    if a.kind == b.kind == "line_mass":  # masses along one stretch of a side add up
        return _segment_gap(a.geometry["segment"], b.geometry["segment"]) <= reach
    if {a.kind, b.kind} == {"point_mass", "line_mass"}:
        line, point = (a, b) if a.kind == "line_mass" else (b, a)
        return _to_segment(np.asarray(point.at, float)[:2], np.asarray(line.geometry["segment"], float)) <= reach
    return False


def _to_segment(p, seg) -> float:
    """Distance [m] from point ``p`` to the straight segment ``seg`` (2, 2)."""
    a, b = seg[:1], seg[1:]
    return float(np.linalg.norm(a + segment_parameter(p[None], a, b)[:, None] * (b - a) - p))


def _segment_gap(s, t) -> float:
    """Shortest distance [m] between two straight segments (0 where they overlap or cross)."""
    s, t = np.asarray(s, float), np.asarray(t, float)

    def side(a, b, p):  # sign of p's side of the line a-b
        (u, v), (w, z) = b - a, p - a
        return np.sign(u * z - v * w)

    if side(*s, t[0]) * side(*s, t[1]) < 0 and side(*t, s[0]) * side(*t, s[1]) < 0:
        return 0.0  # they cross
    return min([_to_segment(p, t) for p in s] + [_to_segment(p, s) for p in t])


def _neighbours(chosen, reach: float) -> list:
    """Groups of chosen effects linked (:func:`_linked`) directly or through others, reported as one."""
    from scipy.sparse.csgraph import connected_components

    n = len(chosen)
    link = np.eye(n, dtype=bool)
    for a in range(n):
        for b in range(a + 1, n):
            link[a, b] = link[b, a] = _linked(chosen[a], chosen[b], reach)
    _, label = connected_components(link, directed=False)
    return [np.flatnonzero(label == g).tolist() for g in dict.fromkeys(label.tolist())]


def _merged(chosen, values, cov, cov_jack, group) -> dict:
    """One effect entry (JSON-ready) for a group: the magnitudes summed at their weighted centre (on
    line masses: the place and extent of the largest; parallel stiffeners: their weighted mean
    path; overlapping regions: the mean change over the area they cover, their union, which keeps
    the change's integral over the board), the uncertainty of that combination from the fit's
    covariance ``cov``, the jackknife's ``cov_jack`` and the model-form budget
    (:func:`.uncertainty.parts`)."""
    lines = [k for k in group if chosen[k].kind == "line_mass"]
    c = chosen[max(lines, key=lambda k: values[k]) if lines else group[0]]
    d = c.describe()
    v = np.asarray(values, float)[group]
    w = np.ones(v.size)  # the combination reported: a sum, or for regions an area-weighted mean
    if len(group) > 1:
        d["name"] = "+".join(chosen[k].name for k in group)
        d["merged_at_mm"] = np.round(1e3 * np.array([chosen[k].at for k in group]), 3).tolist()
        if c.kind == "region_stiffness":
            boxes = [shapely.box(*_rectangle(chosen[k])) for k in group]
            union = shapely.union_all(boxes)
            w = np.array([b.area for b in boxes]) / union.area
            d["polygon_mm"] = np.round(1e3 * np.asarray(union.exterior.coords)[:-1], 3).tolist()
            d["at_mm"] = np.round(1e3 * np.asarray(union.centroid.coords)[0], 3).tolist()
        elif not lines:
            d["at_mm"] = np.round(1e3 * weighted_centre([chosen[k] for k in group], v), 3).tolist()
        if c.kind == "stiffener":
            d["path_mm"] = np.round(1e3 * _mean_path([chosen[k] for k in group], v), 3).tolist()
    sub = np.ix_(group, group)
    u = parts(float(w @ v), w, cov[sub] if cov.size else cov, cov_jack[sub])
    d.update(magnitude=float(w @ v), uncertainty=u.pop("total"), uncertainty_parts=u, kind=c.kind)
    return d


def _mean_path(stiffeners, values) -> np.ndarray:
    """The line (2, 2) [m] of parallel ``stiffeners`` fitted as shares of one rib: their end
    points' mean weighted by their ``values`` (EI)."""
    v = np.asarray(values, float)
    share = v / v.sum() if v.sum() > 0 else np.full(v.size, 1.0 / v.size)
    paths = np.array([np.asarray(c.geometry["path"], float)[[0, -1]] for c in stiffeners])
    return np.einsum("g,gij->ij", share, paths)


def _evidence(res, state, cands) -> dict:
    """{kind: (xy, chi^2 removed)} for the node kinds: the linear chi^2 drop of a candidate at each
    node, the declared parameters projected out (the map of where the residual points)."""
    out = {}
    for name in ("point_mass", "ground_spring"):
        idx = [i for i, c in enumerate(cands) if c.kind == name]
        if not idx:
            continue
        A = res.effect_columns(state, [cands[i] for i in idx])
        P = res.param_columns(state)
        if P.shape[1]:
            Q, _ = np.linalg.qr(P)
            A, r = A - Q @ (Q.T @ A), state.r - Q @ (Q.T @ state.r)
        else:
            r = state.r
        n2 = np.einsum("ij,ij->j", A, A)
        gain = np.where(n2 > 0, (A.T @ r) ** 2 / np.where(n2 > 0, n2, 1.0), 0.0)
        gain[(A.T @ r) < 0] = 0.0  # negative magnitudes are not physical
        out[name] = (np.array([cands[i].at for i in idx]), gain)
    return out
