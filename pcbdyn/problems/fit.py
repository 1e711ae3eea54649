"""The one fit of an :class:`~.problem.UpdateProblem`'s parameters against measured modes, which ``pcbdyn
update``, ``calibrate`` and ``wedgelock`` run (and diagnose's parameter stage): from where users start to
the answer, and what it means.

1. Weights: every measured frequency in units of its noise (a uniform bound f %, eq. 5.72: standard
   deviation f / sqrt 3 %, 0.2 % when none is stated) and of the model's own error where known (mesh
   error, in quadrature), so that chi^2 judges the fit (eq. 4.28). A known mesh error (given, or found by
   the mesh check: the model on a mesh twice as fine at the fitted parameters, after which the fit is
   finished) is also taken out: the model is fitted to the frequencies and shapes its own mesh would show
   for the test structure, so that the parameters do not absorb it (a coarse card is too stiff, and a
   fitted guide stiffness comes out soft to make up for it; the correlation tables keep the measured
   frequencies).
2. Shapes: when the frequency equations at the start do not determine every parameter (numerically
   rank-deficient, or a direction whose standard deviation exceeds :data:`.verdict.UNDETERMINED_SD`) and the test
   has shapes, the shapes join the objective (:mod:`pcbdyn.updating.shapes`, method "modal"), in units of
   their stated noise (when none is stated: 2 % to start with, then what the fit's shape residual shows,
   :func:`shape_noise_estimate`, and the fit finished with that).
3. Starts: parameters on a log scale or with wide bounds are scanned (:mod:`pcbdyn.updating.scan`); each
   basin found is fitted, the best kept and the others reported.
4. The fit: the trust-region iteration of :func:`pcbdyn.updating.driver.update`, its modes paired by MAC
   without the frequency limit (:data:`pcbdyn.correlation.pairing.FREQ_LIMIT`: from tens of percent off
   few pairs are within it; the trust region keeps a pair the linearisation misreads from doing harm),
   the correlation tables with it.
5. The verdict, the first that applies: "cannot fit" (chi^2 above what its degrees of freedom allow at
   :data:`.verdict.ALPHA_FIT`, or fewer than :data:`.verdict.MIN_PAIRED` of the measured modes paired), "error grew" (a configuration ends worse than it started), "on a bound", "not
   determined" (with the direction the data leave open), "not converged", "converged". Only a
   "converged" fit succeeded.

Typical use::

    prob = UpdateProblem(load_structure("board.toml"))
    res = fit(prob, [(None, read_uff("test.uff").modes)], noise=(0.2, 2.0))
    res.status, res.values, res.after, res.verdict
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from ..correlation.pairing import FREQ_LIMIT
from ..updating.driver import update
from ..updating.iteration import build_equations
from ..updating.scan import scan, scanned
from ..updating.solvers import RankDeficiencyWarning
from .error_budget import model_errors, noise_sigma
from .run import TOL_FREQ_PCT, correlation_state, pairing_warnings
from .verdict import judge, values_text, verdict, weak_directions

#: frequency and shape noise [%] (uniform bounds, eqs. 5.72-5.73) assumed when a test states none
DEFAULT_NOISE = (0.2, 2.0)


@dataclass
class Fit:
    """What :func:`fit` found. ``p``: the parameters [SI]; ``result``: the kept start's
    :class:`~pcbdyn.updating.driver.UpdateResult`; ``before``/``after``: correlation states (:func:`.run.
    correlation_state`) at the start and at ``p``; ``status`` and ``details`` (module docstring);
    ``verdict``: chi^2, degrees of freedom, probability and whether the model fits; ``starts``: every
    start fitted (start, end, objective, kept); ``shapes``: why shapes joined the objective (None when they
    did not); ``noise``: the noise used and whether it was stated; ``at_bounds`` {name: side},
    ``undetermined``: the directions the data leave open; ``configs``: the configurations fitted (their
    equations at ``p`` give the covariance)."""

    problem: object
    configs: list
    p: np.ndarray
    result: object
    before: list
    after: list
    status: str
    details: list
    verdict: dict
    noise: dict
    starts: list = field(default_factory=list)
    scan: dict | None = None
    shapes: str | None = None
    at_bounds: dict = field(default_factory=dict)
    undetermined: list = field(default_factory=list)
    worse: list = field(default_factory=list)

    @property
    def succeeded(self) -> bool:
        return self.status == "converged"

    @property
    def values(self) -> dict:
        return self.problem.values(self.p)

    @property
    def warnings(self) -> list:
        """The pairing's warnings before and after (:func:`.run.pairing_warnings`)."""
        return pairing_warnings(self.before + self.after)

    def summary(self) -> dict:
        """The JSON-ready account of the fit (status, verdict, noise, starts, shapes)."""
        return {"status": self.status, "details": self.details, "verdict": self.verdict, "noise": self.noise,
                "shapes_in_objective": self.shapes, "scan": self.scan,
                "starts": [{"start": self.problem.values(s["start"]), "end": self.problem.values(s["end"]),
                            "objective": s["objective"], "unpaired": s["unpaired"], "kept": s["kept"]}
                           for s in self.starts]}


def _tests(measured) -> list:
    """[(structure index, configuration, Modes)] from (configuration, Modes) or (structure, configuration,
    Modes) tuples."""
    return [(0, *m) if len(m) == 2 else tuple(m) for m in measured]


def _corrected(modes, model_pct, shapes=None):
    """``modes`` as the model's mesh would show them: each frequency moved by the model's own relative error
    ``model_pct`` [%], and with ``shapes`` (the mesh's change of each model shape and the shape,
    :func:`.error_budget.model_errors`) each shape by that change, scaled as the measured shape is to the
    model's."""
    f = modes.frequencies * (1.0 + np.asarray(model_pct, float) / 100.0)
    if shapes is None or modes.shapes is None:
        return replace(modes, frequencies=f)
    _, change, u = shapes
    uu = np.einsum("ij,ij->j", u, u)
    scale = np.divide(np.einsum("ij,ij->j", modes.shapes, u), uu, out=np.zeros_like(uu), where=uu > 0)
    return replace(modes, frequencies=f, shapes=modes.shapes + change * scale[None, :])


def frequency_sigma(modes, f_pct: float, model_pct=None) -> np.ndarray:
    """Standard deviation [Hz] of each measured frequency: the uniform bound ``f_pct`` / sqrt 3 and the
    model error ``model_pct`` (per measured mode, %) in quadrature."""
    rel = np.full(modes.frequencies.size, 100.0 * noise_sigma(f_pct))
    if model_pct is not None:
        rel = np.hypot(rel, np.abs(np.asarray(model_pct, float)))
    return rel / 100.0 * modes.frequencies


def configurations(problem, tests, method: str, f_pct: float, shape_pct: float, model=None,
                   min_mac: float = 0.5, corrected: bool = False, limit: float = FREQ_LIMIT) -> list:
    """The driver configurations of ``tests`` for ``method``: "freq" (frequencies, MAC-paired with shapes),
    "modal" (frequencies and shapes), "qms"/"fbm" (one per measured mode, :meth:`~.problem.UpdateProblem.
    mode_configurations`); frequencies weighted by :func:`frequency_sigma`, shapes by their noise. ``model``:
    the model's own errors (frequencies [%], signed; shapes, relative, or None), per test configuration and
    measured mode (:func:`.error_budget.model_errors`), in the noise and, with ``corrected``, taken out of
    the measured frequencies. ``limit``: pairs further apart in frequency are left out (relative). Test modes
    the frequency noise alone cannot tell apart are compared as a plane (``noise_f``: in the "modal" shape
    rows and in every MAC reported)."""
    out = []
    f_model, s_model = model if model is not None else ([None] * len(tests), [None] * len(tests))
    for (k, c, m), e, es in zip(tests, f_model, s_model):
        sig = frequency_sigma(m, f_pct, e)
        m = _corrected(m, e, es) if corrected and e is not None else m
        if method in ("qms", "fbm"):
            out += problem.mode_configurations(c, m, method, min_mac=min_mac, structure=k)
        elif method == "modal":
            rel = noise_sigma(shape_pct)
            out.append(problem.configuration(c, m, "modal", min_mac=min_mac, structure=k, sigma=sig, limit=limit,
                                             shape_noise=rel if es is None else np.hypot(rel, es[0]),
                                             noise_f=frequency_sigma(m, f_pct)))
        else:
            out.append(problem.configuration(c, m, "freq", min_mac=min_mac, structure=k, sigma=sig, limit=limit,
                                             noise_f=frequency_sigma(m, f_pct)))
    return out


def fit(problem, measured, *, method: str = "freq", noise=(None, None), shapes: str = "auto",
        scan_start: bool = True, model_pct=None, mesh_check: bool = False, solver: str = "bounded",
        max_iter: int = 20, tol_freq_pct: float = TOL_FREQ_PCT, tol_param_pct: float = 0.5, min_mac: float = 0.5,
        progress=None) -> Fit:
    """Fit the parameters of ``problem`` to measured modes: the weighted least squares of the frequency
    (and shape) residuals in units of their noise, judged by chi^2 against its degrees of freedom
    (thesis eq. 4.28); the steps are in the module docstring.

    Parameters
    ----------
    problem : UpdateProblem
        The structures and the parameters updated; its ``p0`` is the start.
    measured : list
        [(configuration or None, :class:`pcbdyn.testdata.MeasuredModes`)], or [(structure index,
        configuration, modes)] for several structures.
    noise : (float or None, float or None)
        Uniform noise bounds of the frequencies and shapes [%]; None where the test does not state it.

    Returns
    -------
    Fit
        ``values`` {name: value [SI]}, ``p``, ``status`` ("converged" when it succeeded), ``verdict``
        (chi^2, degrees of freedom, probability), ``before``/``after`` correlation states.

    Examples
    --------
    A card whose PGAs are 20 % thicker (4.2 mm) than its board.toml says (3.5 mm):

    >>> from pcbdyn.board import load_board
    >>> from pcbdyn.fe.modal import solve_modes
    >>> from pcbdyn.problems import UpdateProblem
    >>> from pcbdyn.testdata import Noise, read_points_csv
    >>> from pcbdyn.testdata.simulate import simulate_on_model
    >>> card = "examples/six_part_card/"
    >>> board = load_board(card + "board.toml")
    >>> truth = board.build().with_parameters({"t_PGA": 4.2e-3}).model
    >>> points, dofs = read_points_csv(card + "points.csv")
    >>> test = simulate_on_model(truth, solve_modes(truth, n_modes=7), points, dofs,
    ...                          noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=1)
    >>> result = fit(UpdateProblem(board, ["t_PGA"]), [(None, test.modes)], noise=(0.2, 2.0))
    >>> result.status, round(result.values["t_PGA"] * 1e3, 2)          # mm
    ('converged', 4.21)

    Notes
    -----
    ``method``: "freq" (shapes added when ``shapes`` is "auto" and the frequencies leave a direction
    open, always with "always", never with "never"), "modal", "qms" or "fbm". ``noise``: (frequency %,
    shape %) uniform bounds, None where not stated (:data:`DEFAULT_NOISE`). ``scan_start``: scan log-scale
    and wide parameters first. ``model_pct``: per test configuration, the model's own error of each
    measured mode [%] (its mesh error: f(h) / f(converged) - 1), taken out of the data and added to the
    noise. ``mesh_check``: at the fitted parameters, the model on a mesh twice as fine gives the mesh's
    errors of the frequencies and shapes (:func:`.error_budget.model_errors`), and the fit is finished
    with them (in place of ``model_pct``). ``progress(message)``: what is being done and each iteration."""
    tests = _tests(measured)
    say = progress or (lambda msg: None)
    stated = tuple(v is not None for v in noise)
    f_pct, shape_pct = (v if v is not None else d for v, d in zip(noise, DEFAULT_NOISE))
    model = None if model_pct is None else (model_pct, [None] * len(tests))
    check = configurations(problem, tests, "freq", f_pct, shape_pct, model, min_mac)
    base = configurations(problem, tests, "freq", f_pct, shape_pct, model, min_mac, model is not None, np.inf)
    why = None
    if method == "freq" and all(m.shapes is not None for _, _, m in tests) and shapes != "never":
        weak = weak_directions(base, problem.p0, problem.names) if shapes == "auto" else ["asked for"]
        if weak:
            why = ("asked for" if shapes == "always" else
                   f"the frequencies at the start do not determine {'; '.join(weak)}")
            method = "modal"
            say(f"mode shapes join the objective: {why}")

    def build(model):  # MAC alone pairs in a fit: from tens of percent off, no pair is within the limit
        return configurations(problem, tests, method, f_pct, shape_pct, model, min_mac, model is not None, np.inf)

    cfgs = build(model)
    ranges = scanned(problem.p0, problem.bounds, problem.log_scale) if scan_start else []
    sc = scan(cfgs, problem.p0, ranges, progress=say) if ranges else None
    starts = sc.starts if sc is not None else [problem.p0]
    tol = (max_iter, tol_freq_pct, tol_param_pct)
    runs = [_run(problem, cfgs, p0, k, len(starts), solver, tol, say) for k, p0 in enumerate(starts)]
    keys = [(r.history[-1]["unpaired"], r.history[-1]["objective"]) for r in runs]
    best = min(range(len(runs)), key=lambda k: keys[k])
    res = runs[best]
    if method == "modal" and not stated[1]:
        shape_pct = shape_noise_estimate(cfgs, res.p)
        say(f"the shapes' residual says their noise is {shape_pct:.3g} % (uniform bound): refitted with it")
        cfgs = build(model)
        res = _more(res, _run(problem, cfgs, res.p, 0, 1, solver, tol, say))
    if mesh_check:
        say("the model on a mesh twice as fine at the fitted parameters (its mesh error)")
        model = model_errors(problem, tests, res.p, correlation_state(check, res.p))
        cfgs = build(model)
        check = configurations(problem, tests, "freq", f_pct, shape_pct, model, min_mac)
        res = _more(res, _run(problem, cfgs, res.p, 0, 1, solver, tol, say))
    runs[best], keys[best] = res, (res.history[-1]["unpaired"], res.history[-1]["objective"])
    before, after = correlation_state(check, problem.p0), correlation_state(check, res.p)
    judged = cfgs if method in ("freq", "modal") else configurations(problem, tests, "freq", f_pct, shape_pct, model,
                                                                     min_mac, model is not None, np.inf)
    out = Fit(problem, cfgs, res.p, res, before, after, "", [], verdict(judged, res.p, problem),
              {"frequency_pct": f_pct, "shape_pct": shape_pct if method == "modal" else None,
               "shape_estimated": method == "modal" and not stated[1],
               "stated": list(stated), "model_error": model is not None},
              [{"start": s, "end": r.p, "objective": key[1], "unpaired": key[0], "kept": k == best}
               for k, (s, r, key) in enumerate(zip(starts, runs, keys))],
              None if sc is None else sc.to_dict(problem.names), why)
    judge(out, cfgs if method in ("freq", "modal") else None)
    return out


def _more(res, more):
    """The run ``more`` that went on from ``res``'s end, its history joined to ``res``'s."""
    history = res.history + [{**h, "iteration": len(res.history) + k} for k, h in enumerate(more.history[1:])]
    return replace(more, history=history, iterations=len(history) - 1, best_iteration=len(history) - 1)


def shape_noise_estimate(cfgs, p) -> float:
    """The shape noise [%, uniform bound] the residual of the paired shapes of the "modal" ``cfgs`` at ``p``
    shows: sqrt 3 times the rms of each mode's residual relative to its rms, over the modes (the model's
    error in the shapes counts in it, as it should in their weight)."""
    (_, _), _, states = build_equations(cfgs, p)
    ratios = []
    for c, st in zip(cfgs, states):
        if c.method != "modal" or st.get("set_aside"):
            continue
        for a, k in enumerate(st["used"]):
            d, u = np.asarray(c.phi_x, float)[:, k], st["phi_am"][:, a]
            r = d - (u @ d) / (u @ u) * u
            ratios.append(np.mean(r**2) / np.mean(d**2))
    return float(100.0 * math.sqrt(3.0 * np.mean(ratios)))


def _run(problem, cfgs, p0, k, n, solver, tol, say):
    """The driver's fit from ``p0`` (start ``k`` of ``n``); ``tol``: (max_iter, tol_freq_pct, tol_param_pct)."""
    if n > 1:
        say(f"start {k + 1} of {n}: {values_text(problem, p0)}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RankDeficiencyWarning)
        return update(cfgs, p0, solver=solver, bounds=problem.bounds, log_scale=problem.log_scale,
                      max_iter=tol[0], tol_freq_pct=tol[1], tol_param_pct=tol[2],
                      progress=lambda h: say(_progress_line(h)))


def _progress_line(h) -> str:
    err = "" if h["max_freq_error_pct"] is None else f"max |df| {h['max_freq_error_pct']:.3f} %, "
    aside = f"; set aside: {', '.join(h['set_aside'])}" if h.get("set_aside") else ""
    lost = f"{h['unpaired']} measured mode(s) unpaired, " if h["unpaired"] else ""
    return f"iteration {h['iteration']}: {err}{lost}chi^2 {h['objective']:.4g}{aside}"
