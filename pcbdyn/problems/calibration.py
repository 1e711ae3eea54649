"""Calibrating part families of the component library from modal tests (thesis section 7.3).

A calibration is an :class:`~.problem.UpdateProblem` over one or more boards: each board carries one
parameter per calibrated family whose targets are the ``components.<ref>.thickness`` of that family's
parts on that board, so every part of a family, on every board, shares one equivalent thickness; the
region density follows eq. 7.7, so each part keeps its mass whatever the thickness. The parts start
from the library's value. Extra parameters (``--with board.E``) are fitted beside the families, one per
board. The fit uses the existing methods (freq, qms, fbm), configurations (PBC) and solvers.

The standard deviation of each value comes from the posterior covariance of the fit
(:func:`pcbdyn.updating.solvers.covariance`) on the last equations, weighted by the test noise:
stated (uniform bounds in percent, thesis eqs. 5.72-5.73: standard deviation bound / sqrt 3; for
shape equations the rows' noise is measured by redrawing it on the data, a parametric bootstrap) or,
when none is stated, estimated from the residual. A stated noise never makes the estimate surer than
the fit's own residual says (s^2 >= 1), so model error shows in the standard deviation too. What the
mesh does to each mode (:mod:`.error_budget`) adds a systematic part, kept apart in the library
record, since it does not average out over runs on similar meshes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .. import targets
from ..components.library import locate, read_package, search_path
from ..domain import StructureError
from ..testdata.noise import add_noise
from ..updating.driver import at_bounds
from ..updating.iteration import build_equations
from ..updating.solvers import covariance
from ..updating.weighting import NOISE_REDRAWS
from .error_budget import measured_mesh_steps, noise_sigma
from .fit import fit
from .verdict import MIN_PAIRED
from .problem import UpdateProblem
from .run import correlation_state

#: a family parameter is bounded to [value / FAMILY_RANGE, value * FAMILY_RANGE]
FAMILY_RANGE = 3.0
#: an extra (``--with``) parameter is bounded to [value / r, value * r]: r = 2, springs (log scale) 100
WITH_RANGE = (2.0, 100.0)
METHODS = ("freq", "qms", "fbm")


class CalibrationError(StructureError):
    """A calibration that cannot be set up; the message names the file, the family and the fix."""


@dataclass
class BoardTests:
    """A structure and its tests: ``tests`` [(configuration or None, Modes)] read from ``files``
    [(configuration or None, Path)] (one file per configuration, or a table of frequencies)."""

    structure: object
    tests: list
    files: list


@dataclass
class Calibration:
    """A calibration's problem, fit and result: ``families`` (the family parameter names, first in
    ``problem.names``), ``start`` {family: (value [m], library file it came from)}, ``result``
    (:class:`~pcbdyn.updating.driver.UpdateResult`), ``before``/``after`` correlation states,
    ``std`` [SI] of every parameter and ``std_mesh``, the part of it the mesh makes (a systematic error,
    common to every run on meshes alike), ``at_bound`` and ``undetermined`` parameter names, ``mesh_steps``
    (per test configuration, the relative change h -> h/2 of each measured mode's model frequency),
    ``noise`` (how the standard deviations were found) and ``fit`` (:class:`~.fit.Fit`: status, verdict)."""

    problem: UpdateProblem
    families: list
    start: dict
    items: list
    method: str
    solver: str
    result: object = None
    before: list = field(default_factory=list)
    after: list = field(default_factory=list)
    std: np.ndarray | None = None
    std_mesh: np.ndarray | None = None
    at_bound: list = field(default_factory=list)
    undetermined: list = field(default_factory=list)
    mesh_steps: list = field(default_factory=list)
    noise: str = ""
    fit: object = None

    def value(self, name) -> float:
        return float(self.result.p[self.problem.names.index(name)])

    def sd_mesh(self, name) -> float:
        return float(self.std_mesh[self.problem.names.index(name)]) if self.std_mesh is not None else 0.0

    def sd(self, name) -> float:
        return float(self.std[self.problem.names.index(name)])


def families_on(structure) -> dict:
    """{family: [parts]} of the parts of ``structure`` that come from a library package."""
    out: dict = {}
    for c in getattr(structure, "components", []):
        if c.package is not None:
            out.setdefault(c.package, []).append(c)
    return out


def library_start(families, board_dir=None) -> dict:
    """{family: (equivalent thickness [m], library file)} from the library search path; a family no
    library folder has is a CalibrationError."""
    out = {}
    for fam in families:
        path = locate(fam, board_dir)
        if path is None:
            where = ", ".join(str(d) for d in search_path(board_dir))
            raise CalibrationError(f"family '{fam}' is not in the library (searched {where}); add {fam}.toml to "
                                   "the library folder or leave it out of --families")
        out[fam] = (read_package(path).equivalent_thickness, path)
    return out


def choose_families(structures, wanted=None) -> list:
    """The families to calibrate: ``wanted`` (each on some structure, every part of it an
    equivalent_thickness part) or, by default, every family whose parts all use that model."""
    on = {}
    for s in structures:
        for fam, parts in families_on(s).items():
            on.setdefault(fam, []).extend((s, c) for c in parts)
    files = ", ".join(s.path.name for s in structures)
    if wanted is None:
        wanted = [f for f, parts in on.items() if all(c.model == "equivalent_thickness" for _, c in parts)]
        if not wanted:
            raise CalibrationError(f"{files}: no part family with equivalent_thickness parts to calibrate "
                                   f"(families: {', '.join(on) or 'none'}); give parts a library package")
        return wanted
    for fam in wanted:
        if fam not in on:
            raise CalibrationError(f"--families: no part of {files} is of family '{fam}' (families on the "
                                   f"board{'s' if len(structures) > 1 else ''}: {', '.join(on) or 'none'})")
        other = [(s, c) for s, c in on[fam] if c.model != "equivalent_thickness"]
        if other:
            s, c = other[0]
            raise CalibrationError(f"{s.path.name}: part {c.ref} of family '{fam}' uses model '{c.model}'; a "
                                   "calibration fits the equivalent thickness (eq. 7.7): remove its model = ... "
                                   "or leave the family out of --families")
    return list(wanted)


def family_structure(structure, start: dict, extra=(), parts=None):
    """``structure`` with the parts of each family of ``start`` {family: (value, file)} at that value
    and one parameter per family on it (targets: its parts' thicknesses), then the ``extra`` specs.
    ``parts`` {family: [parts]}: the parts that take the family value (default: all of the family)."""
    parts = families_on(structure) if parts is None else parts
    chosen = {c.ref: fam for fam, cs in parts.items() if fam in start for c in cs}
    comps = [replace(c, thickness=start[chosen[c.ref]][0]) if c.ref in chosen else c for c in structure.components]
    s = replace(structure, components=comps, parameters=[])
    specs = []
    for fam, (value, _) in start.items():
        if not parts.get(fam):
            continue
        lo, hi = value / FAMILY_RANGE, value * FAMILY_RANGE
        entry = {"name": fam, "target": [targets.target("components", c.ref, "thickness") for c in parts[fam]],
                 "bounds": [targets.quantity(lo, "mm"), targets.quantity(hi, "mm")]}
        specs.append(targets.parameter_spec(entry, f"family {fam}", s.quantity, structure.path.name))
    return replace(s, parameters=specs + list(extra))


def with_spec(structure, item: str, name: str, families=()) -> targets.ParameterSpec:
    """The extra parameter ``item`` (a ``[[parameters]]`` name of ``structure`` or a target such as
    ``board.E``) called ``name``: the structure's own bounds when it declares it, else the current
    value times/over :data:`WITH_RANGE`."""
    own = next((p for p in structure.parameters if p.name == item or p.targets == [item]), None)
    if own is not None:
        return replace(own, name=name)
    tg = targets.parse(item)
    if tg.collection == "components" and (c := structure.component(tg.name)) is not None and c.package in families:
        raise CalibrationError(f"--with {item}: part {c.ref} is calibrated with its family '{c.package}'")
    v = structure.quantity(item)
    if v is None:
        raise CalibrationError(f"--with {item}: {structure.path.name} has no such quantity ({tg.kind.what}); "
                               f"give a parameter name or a target of the board ({targets.known()})")
    r = WITH_RANGE[1] if tg.kind.log else WITH_RANGE[0]
    entry = {"name": name, "target": item,
             "bounds": [targets.formatted(tg.kind, v / r), targets.formatted(tg.kind, v * r)]}
    return targets.parameter_spec(entry, f"--with {item}", structure.quantity, structure.path.name)


def calibration_problem(items, families=None, with_=(), mesh_size=None) -> Calibration:
    """The :class:`Calibration` (not yet fitted) of ``items`` (:class:`BoardTests`): the families
    (:func:`choose_families`) from their library values, plus ``with_`` parameters on every board."""
    structures = [it.structure for it in items]
    if families is not None:
        library_start(families, structures[0].path.parent)  # a family nowhere in the library, before the boards
    fams = choose_families(structures, families)
    start = library_start(fams, structures[0].path.parent)
    several = len(items) > 1
    new = []
    for it in items:
        s = it.structure
        extra = [with_spec(s, w, f"{w}@{s.path.stem}" if several else w, fams) for w in with_]
        new.append(replace(it, structure=family_structure(s, start, extra)))
    names = fams + [p.name for it in new for p in it.structure.parameters if p.name not in fams]
    problem = UpdateProblem([it.structure for it in new], names, mesh_size=mesh_size)
    return Calibration(problem, fams, start, new, "", "")


def configurations(problem, items, method: str, modify=None) -> tuple:
    """(check, fit): full-model frequency configurations of every test (MAC pairing with shapes; rows
    weighted by the measured frequency, so every mode's relative error counts alike), and the
    configurations fitted (the same for freq; one per measured mode for qms/fbm). ``modify`` maps
    each measured Modes first (noise redraws)."""
    check, fit = [], []
    for k, it in enumerate(items):
        for c, m in it.tests:
            m = m if modify is None else modify(m)
            check.append(problem.configuration(c, m, "freq", structure=k, sigma=m.frequencies))
            if method != "freq":
                fit += problem.mode_configurations(c, m, method, structure=k)
    return check, (check if method == "freq" else fit)


def config_labels(items) -> list:
    """'file (board, configuration)' of every test configuration, in the order of :func:`configurations`."""
    return [f"{path.name} ({it.structure.path.name}, configuration {c or 'base'})"
            for it in items for c, path in it.files]


def check_pairing(cal: Calibration, check) -> None:
    """A CalibrationError when, at the start, a test's modes do not pair with its board's (fewer than
    :data:`.verdict.MIN_PAIRED` of them by MAC: a test of another board, or points in another frame; without
    shapes, by number: none at all)."""
    for cfg, label in zip(check, config_labels(cal.items)):
        try:
            state = correlation_state([cfg], cal.problem.p0)[0]
        except ValueError:
            state = {"pairs": []}
        n = int(np.size(cfg.f_x))
        if len(state["pairs"]) < max(1, math.ceil(MIN_PAIRED * n)) and (cfg.phi_x is not None or not state["pairs"]):
            how = "by MAC (>= 0.5)" if cfg.phi_x is not None else "by number"
            raise CalibrationError(f"{label}: only {len(state['pairs'])} of its {n} measured modes pair with the "
                                   f"model's {how}; is it a test of this board? Check the test file, the board "
                                   "and the frame of the measurement points")


def calibrate(cal: Calibration, method: str = "freq", solver: str = "bounded", noise=(None, None),
              mesh_error: bool = True, seed: int = 0, **fit_options) -> Calibration:
    """Fit ``cal`` with ``method`` and ``solver`` through :func:`.fit.fit` (``fit_options``: max_iter,
    tol_freq_pct, tol_param_pct, progress; the shapes stay out of a frequency calibration and the data
    keep the mesh's error, which the calibrated value absorbs, module docstring) and give every parameter
    its standard deviation (``noise`` = (frequency %, shape %), uniform bounds, None where not stated).
    With ``mesh_error`` what the model's mesh does to each paired mode (:mod:`.error_budget`) joins the
    covariance as a systematic error. Returns ``cal`` filled in, its :class:`~.fit.Fit` as ``cal.fit``."""
    if method not in METHODS:
        raise CalibrationError(f"--method {method}: a calibration uses one of {', '.join(METHODS)}")
    cal.method, cal.solver = method, solver
    for it in cal.items:
        for (c, m), (_, path) in zip(it.tests, it.files):
            if m.shapes is not None:
                it.structure.check_points(m.measured_points(), path)
            elif method != "freq":
                raise CalibrationError(f"{path.name}: --method {method} needs mode shapes (a UFF test with dataset 55)")
    check, fitted = configurations(cal.problem, cal.items, method)
    check_pairing(cal, check)
    tests = [(k, c, m) for k, it in enumerate(cal.items) for c, m in it.tests]
    cal.fit = fit(cal.problem, tests, method=method, noise=noise, shapes="never", solver=solver, **fit_options)
    cal.result, cal.before, cal.after = cal.fit.result, cal.fit.before, cal.fit.after
    p = cal.result.p
    cov, cal.noise, undetermined = posterior_covariance(cal, fitted, p, noise, seed)
    g = np.zeros(p.size)
    if mesh_error:
        cal.mesh_steps = measured_mesh_steps(cal.problem, cal.items, cal.after, p)
        g = systematic_shift(check, p, cal.mesh_steps)
    cal.std = np.abs(p) * np.sqrt(np.clip(np.diag(cov), 0.0, None) + g**2)
    cal.std_mesh = np.abs(p * g)
    cal.std[undetermined] = np.inf
    cal.undetermined = [cal.problem.names[j] for j in np.flatnonzero(undetermined)]
    cal.at_bound = list(at_bounds(cal.problem.names, p, cal.problem.bounds))
    return cal


def systematic_shift(check, p, sigmas) -> np.ndarray:
    """g: the change of the relative parameters x that a one-sigma error of the model's frequencies
    would make, every mode erring together (a systematic error, such as the mesh's; its covariance is
    g g^T), through the frequency equations at ``p`` with equal relative weights. ``sigmas``: per test
    configuration, the relative standard deviation of each measured mode's model frequency."""
    (_, _), blocks, states = build_equations(check, p)
    A = np.vstack([blk.A / np.asarray(c.f_x, float)[st["used"]][:, None] for c, blk, st in zip(check, blocks, states)])
    u = np.concatenate([np.asarray(s, float)[st["used"]] for s, st in zip(sigmas, states)])
    return np.linalg.pinv(A) @ u


def posterior_covariance(cal: Calibration, fit, p, noise, seed: int = 0) -> tuple:
    """(covariance of the relative changes x = dp/p, description of the noise used, undetermined
    mask) from the fitted equations at ``p``. Frequency rows are weighted by their noise
    (f_pct / sqrt 3 of each frequency, or equal relative noise estimated from the residual); shape
    rows (QMS, FBM) by the noise a redraw of the stated noise makes in them, per mode, or unit rows
    with the noise estimated from the residual."""
    f_pct, shape_pct = noise
    (A, b), blocks, states = build_equations(fit, p)
    if cal.method == "freq":
        rel = 1.0 if f_pct is None else noise_sigma(f_pct)
        d = np.concatenate([1.0 / (rel * np.asarray(cfg.f_x, float)[st["used"]]) for cfg, st in zip(fit, states)])
        A = np.vstack([blk.A for blk in blocks]) * d[:, None]
        b = np.concatenate([blk.b for blk in blocks]) * d
        stated = f_pct is not None
        text = (f"frequency noise {f_pct:g} % stated (uniform bounds)" if stated
                else "noise estimated from the residual (equal relative frequency noise)")
    elif f_pct is None and shape_pct is None:
        stated, text = False, "noise estimated from the residual (unit rows, eq. 4.42)"
    else:
        sigma = _redrawn_row_noise(cal, fit, blocks, p, f_pct, shape_pct, seed)
        A, b = A / sigma[:, None], b / sigma
        stated = True
        text = f"noise stated (f {f_pct or 0:g} %, shape {shape_pct or 0:g} %, uniform bounds), rows weighted by redraws"
    _, s, Vt = np.linalg.svd(A, full_matrices=False)
    null = Vt[s < 1e-10 * s[0]] if s.size and s[0] > 0 else Vt
    undetermined = np.any(np.abs(null) > 0.1, axis=0) if null.size else np.zeros(A.shape[1], bool)
    return covariance(A, b, stated=stated), text, undetermined


def _redrawn_row_noise(cal, fit, blocks, p, f_pct, shape_pct, seed) -> np.ndarray:
    """Standard deviation of every stacked (unit-weighted) row of the shape equations: the rms change
    of each configuration's rows when the stated noise is drawn again on its data
    (:data:`~pcbdyn.updating.weighting.NOISE_REDRAWS` times; eqs. 5.72-5.73)."""
    rng = np.random.default_rng(seed)
    (_, b0), _, _ = build_equations(fit, p)
    sizes = [blk.b.size for blk in blocks]
    sq, n = np.zeros(len(sizes)), 0
    for _ in range(NOISE_REDRAWS):
        def noisy(m):
            return replace(m, frequencies=add_noise(m.frequencies, f_pct or 0.0, rng),
                           shapes=add_noise(m.shapes, shape_pct or 0.0, rng))

        _, redrawn = configurations(cal.problem, cal.items, cal.method, noisy)
        (_, bd), blks, _ = build_equations(redrawn, p)
        if [blk.b.size for blk in blks] != sizes:
            continue  # the noise changed a pairing: not a redraw of these rows
        db = np.split(bd - b0, np.cumsum(sizes)[:-1])
        sq += [float(np.mean(v**2)) for v in db]
        n += 1
    if n == 0:
        raise CalibrationError("the stated noise changes the mode pairing of every redraw; state a smaller noise or "
                               "leave --noise out (the noise is then estimated from the residual)")
    sigma = np.sqrt(sq / n)
    sigma = np.where(sigma > 0, sigma, max(float(sigma.max()), 1e-300))
    return np.repeat(sigma, sizes)
