"""Two-step wedge-lock fitting (thesis section 7.4, summary 7.4.3): a guide holds a card edge somewhere
between hinged and clamped and its stiffness spans decades, so it is not updated blindly from an
arbitrary start.

Step 1 correlates the board with every guide hinged and clamped (:mod:`.extremes`). Clamped is accepted
when it matches every paired test mode within the tolerance: by default what the test noise (a uniform
bound, eq. 5.72) and the model's mesh error (4/3 of the frequency change of a mesh twice as fine) explain,
or a percentage the user gives. Otherwise step 2 (:mod:`.spring_fit`): the guides become rotational
springs, one stiffness shared by all guides (or one per guide), fitted by :func:`.fit.fit` (scanned
between the extremes on a log scale, jointly for the guides, with the shapes in the objective where the
frequencies cannot tell the guides apart), bounded and iterated with re-pairing. One stiffness per guide is fitted when
asked, or when the shared one leaves more than the noise and one per guide explains significantly more.
The springs are kept only when they explain the test significantly better than the clamped edges (F
test, :func:`.spring_fit.significance`); otherwise what is left is not the guides' doing, and the thesis'
verdict on its card (section 7.4.2: "the clamped edge model is quite acceptable") is the answer."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..testdata import TestDataError
from ..updating.driver import evaluate
from ..updating.scan import grid
from . import guides
from .error_budget import noise_explains, noise_sigma
from .extremes import Extreme, correlate_extreme, mesh_errors
from .fit import DEFAULT_NOISE
from .run import pairing_warnings
from .spring_fit import ALPHA, SpringFit, SpringModel, chi2, significance

#: frequency noise [%] (uniform bound, eq. 5.72) assumed when the test states none
DEFAULT_NOISE_PCT = DEFAULT_NOISE[0]


@dataclass(kw_only=True)
class WedgeLockResult:
    """What the two steps found: the extremes, each test mode's tolerance and sigma [%] (per
    configuration {test mode: %}), the ``decision`` ("clamped" or "springs") and its ``reason``, and, when
    step 2 ran, the ``scan`` ({"k": [...], "states": [...]}) and the spring fits (``shared``, ``per_guide``,
    ``chosen``) with the ``tests`` of significance that chose them."""

    board: object
    guides: list
    hinged: Extreme
    clamped: Extreme
    notes: list = field(default_factory=list)
    noise_pct: float
    mesh_pct: list
    tolerance_pct: list
    sigma_pct: list
    clamped_ok: bool = False
    decision: str = ""
    reason: str = ""
    scan: dict | None = None
    shared: SpringFit | None = None
    per_guide: SpringFit | None = None
    chosen: SpringFit | None = None
    tests: dict = field(default_factory=dict)

    def clamped_state(self) -> list:
        """The clamped extreme as a correlation state (per configuration: pairs, max |df|)."""
        return [{"configuration": c["configuration"], "pairs": c["pairs"],
                 "max_freq_error_pct": max((abs(q["df_pct"]) for q in c["pairs"]), default=None)}
                for c in self.clamped.configs]

    def warnings(self) -> list:
        """The pairing's warnings of the extremes and of step 2's start and fit, each once."""
        states = [{"configuration": c["configuration"], "warnings": c.get("warnings", [])}
                  for e in (self.hinged, self.clamped) for c in e.configs]
        return pairing_warnings(states + ([] if self.chosen is None else self.chosen.before + self.chosen.after))

    def before_after(self) -> tuple:
        """(before, after): step 2's start and fit, or the clamped model twice when step 2 did not run."""
        if self.chosen is None:
            return self.clamped_state(), self.clamped_state()
        return self.chosen.before, self.chosen.after

    def k_rot(self) -> dict:
        """{fixture: {value, factor_1sigma, ...}}: the fitted springs, or no value for clamped guides."""
        if self.decision == "springs":
            return {f: {**v, "model": "springs"} for f, v in self.chosen.k_rot().items()}
        return {f: {"value": None, "factor_1sigma": None, "model": "clamped"} for f in self.guides}

    def positions(self) -> list:
        """Per configuration {test mode: where its frequency sits between the extremes, (f_test -
        f_hinged) / (f_clamped - f_hinged): 0 hinged, 1 clamped} for the modes paired at both."""
        out = []
        for ch, cc, c in zip(self.hinged.f_model(), self.clamped.f_model(), self.clamped.configs):
            ft = {q["test_mode"]: q["f_test_hz"] for q in c["pairs"]}
            out.append({t: (ft[t] - ch[t]) / (cc[t] - ch[t]) for t in cc if t in ch and cc[t] != ch[t]})
        return out

    def to_dict(self) -> dict:
        def summary(states):
            errors = [s["max_freq_error_pct"] for s in states if s["max_freq_error_pct"] is not None]
            return {"max_freq_error_pct": max(errors) if errors else None, "configurations": states,
                    "pairs": [{"configuration": s["configuration"], **q} for s in states for q in s["pairs"]]}

        def per_mode(values):
            return [{str(t): v for t, v in d.items()} for d in values]

        before, after = self.before_after()
        fit = self.chosen
        out = {
            "board": self.board.name, "guides": self.guides,
            "extremes": {"hinged": self.hinged.to_dict(), "clamped": self.clamped.to_dict()},
            "noise_pct": self.noise_pct, "mesh_error_pct": per_mode(self.mesh_pct),
            "tolerance_pct": per_mode(self.tolerance_pct), "sigma_pct": per_mode(self.sigma_pct),
            "between_extremes": per_mode(self.positions()),
            "clamped_within_tolerance": self.clamped_ok, "decision": self.decision, "reason": self.reason,
            "notes": self.notes, "warnings": self.warnings(), "k_rot": self.k_rot(),
            "per_guide": fit is not None and fit is self.per_guide,
            "before": summary(before), "after": summary(after), "significance": self.tests,
            "start": {} if fit is None else fit.by_fixture(fit.problem.p0),
            "history": [] if fit is None else [
                {"iteration": h["iteration"], "k_rot": fit.by_fixture(h["p"]),
                 "max_freq_error_pct": h["max_freq_error_pct"], "residue_pct": 100.0 * h["sigma"]}
                for h in fit.result.history],
            "fits": {name: {"k_rot": f.k_rot(), "chi2": f.chi2, "modes": f.n, "iterations": f.result.iterations,
                            "converged": bool(f.result.converged), "reason": f.result.reason, "notes": f.notes,
                            "status": f.fit.status, "verdict": f.fit.verdict, "starts": f.fit.summary()["starts"],
                            "shapes_in_objective": f.fit.shapes,
                            "chosen": f is fit, "max_freq_error_pct": f.max_freq_error_pct}
                     for name, f in (("shared", self.shared), ("per_guide", self.per_guide)) if f is not None},
        }
        if self.scan is not None:
            out["scan"] = {"k": self.scan["k"], "configurations": [
                {"configuration": c["configuration"], "test_modes": [
                    {"test_mode": q["test_mode"], "f_test_hz": q["f_test_hz"],
                     "f_model_hz": scan_frequencies(self.scan["states"], k, q["test_mode"])}
                    for q in c["pairs"]]} for k, c in enumerate(self.clamped.configs)]}
        return out


def scan_frequencies(states, config: int, test_mode: int) -> list:
    """The model frequency [Hz] paired with ``test_mode`` of configuration ``config`` at every scanned
    stiffness (None where it does not pair)."""
    out = []
    for st in states:
        q = None if st is None else next((q for q in st[config]["pairs"] if q["test_mode"] == test_mode), None)
        out.append(None if q is None else q["f_model_hz"])
    return out


def _noise_and_tolerance(tests, mesh, noise, tol_pct) -> tuple:
    """Per configuration {test mode: sigma [%]} (the noise's standard deviation and the mesh error in
    quadrature) and {test mode: tolerance [%]} (noise bound plus mesh error, or ``tol_pct``)."""
    sigma, tol = [], []
    for (_, test), m in zip(tests, mesh):
        modes = range(1, test.n_modes + 1)
        sigma.append({t: float(np.hypot(100.0 * noise_sigma(noise), m.get(t, 0.0))) for t in modes})
        tol.append({t: float(tol_pct if tol_pct is not None else noise + abs(m.get(t, 0.0))) for t in modes})
    return sigma, tol


def _too_few(n: int, need: int, what: str, clamped: Extreme) -> TestDataError:
    return TestDataError(
        f"{n} test mode(s) pair with the model: too few to fit {what} (it needs {need}: one per stiffness and one "
        f"more to check the fit). The clamped guides miss the test by up to {clamped.max_abs_freq_error_pct:.2f} %, "
        "more than the tolerance; no stiffness is reported. Measure more modes (or give --tol if that error is "
        "acceptable)")


def fit_wedge_locks(board, tests, per_guide: bool | None = None, tol_pct: float | None = None,
                    noise_pct: float | None = None, mesh_size: float | None = None, min_mac: float = 0.5,
                    shape_noise_pct: float | None = None,
                    probe_tol: float | None = None, max_iter: int = 20, progress=None) -> WedgeLockResult:
    """The two steps on ``board`` (with wedge_lock fixtures) against ``tests`` [(configuration or None,
    :class:`pcbdyn.testdata.MeasuredModes`)]. ``per_guide``: True fits one stiffness per guide, False one shared,
    None decides from the data. ``tol_pct``: the tolerance that accepts clamped (default noise + mesh
    error); ``noise_pct``: the test's frequency noise (uniform bound, %; default :data:`DEFAULT_NOISE_PCT`);
    ``shape_noise_pct``: its shape noise (uniform bound, %; default :data:`.fit.DEFAULT_NOISE`'s), which
    weighs the shapes when they join the objective.
    A TestDataError when no test mode pairs with either extreme or when too few pair to fit."""
    say = progress or (lambda msg: None)
    names = [f.name for f in guides.wedge_locks(board)]
    h = mesh_size or board.mesh_size
    noise = DEFAULT_NOISE_PCT if noise_pct is None else float(noise_pct)
    say("step 1: every guide hinged, then clamped")
    hinged = correlate_extreme(guides.extreme(board, "hinged"), "hinged", tests, h, min_mac, probe_tol)
    clamped = correlate_extreme(guides.extreme(board, "clamped"), "clamped", tests, h, min_mac, probe_tol)
    paired = [{q["test_mode"] for q in a["pairs"]} | {q["test_mode"] for q in b["pairs"]}
              for a, b in zip(hinged.configs, clamped.configs)]
    if not any(paired):
        raise TestDataError(f"no test mode pairs with the hinged or the clamped model of {board.path.name} (MAC "
                            f"below {min_mac:g} for every mode): the test is not of this board in its guides, or its "
                            "points are not in the board's frame and units; no stiffness can be fitted")
    notes = [f"[{c['configuration']}] test mode(s) {', '.join(map(str, sorted(set(range(1, t.n_modes + 1)) - p)))} "
             "pair with neither extreme and are left out"
             for c, (_, t), p in zip(clamped.configs, tests, paired) if len(p) < t.n_modes]
    if any(t.shapes is None for _, t in tests):
        notes.append("frequencies only: test mode n pairs with model mode n (the thesis pairs by MAC; an extreme "
                     "that reorders the modes pairs differently)")
    say("the clamped model on a mesh twice as fine (its mesh error)")
    fine = correlate_extreme(guides.extreme(board, "clamped"), "clamped", tests, h / 2.0, min_mac, probe_tol)
    mesh = mesh_errors(clamped, fine)
    sigma, tol = _noise_and_tolerance(tests, mesh, noise, tol_pct)
    result = WedgeLockResult(board=board, guides=names, hinged=hinged, clamped=clamped, notes=notes, noise_pct=noise,
                             mesh_pct=mesh, tolerance_pct=tol, sigma_pct=sigma)
    df = clamped.df()
    result.clamped_ok = all(t in d and abs(d[t]) <= tl[t] for d, tl, p in zip(df, tol, paired) for t in p)
    if result.clamped_ok:
        result.decision = "clamped"
        result.reason = (f"the clamped guides match every paired test mode within its tolerance (max |df| "
                         f"{clamped.max_abs_freq_error_pct:.2f} %): no spring model is needed (thesis section 7.4.3)")
        return result
    n_paired = sum(len(p) for p in paired)
    if n_paired < 2 or (per_guide and n_paired < len(names) + 1):
        need = len(names) + 1 if per_guide else 2
        raise _too_few(n_paired, need, "one stiffness per guide" if per_guide else "a stiffness", clamped)
    _step2(result, board, tests, per_guide, (noise_pct, shape_noise_pct), h, min_mac, max_iter, say)
    return result


def _step2(result: WedgeLockResult, board, tests, per_guide, noise, h, min_mac, max_iter, say) -> None:
    """Scan, shared fit, per-guide fit when asked or called for, and the springs-or-clamped test."""
    names, sigma = result.guides, result.sigma_pct
    bounds = guides.stiffness_range(board)
    ks = grid([(0, *bounds)])[0]
    model = SpringModel(board, tests, guides.spring_groups(board, False), bounds, sigma, noise, result.mesh_pct, h,
                        min_mac)
    say(f"step 2: the frequencies at {ks.size} stiffnesses {bounds[0]:.3g}-{bounds[1]:.3g} N*m/rad/m")
    result.scan = {"k": ks.tolist(), "states": model.scan(ks)}
    say(f"fitting one stiffness for {len(names)} guide(s)")
    result.shared = result.chosen = model.fit([float(np.sqrt(bounds[0] * bounds[1]))], max_iter, say)
    shared = result.shared
    if shared.n < 2:
        raise _too_few(shared.n, 2, "a stiffness", result.clamped)
    misfit = not noise_explains(shared.chi2, shared.n - 1, ALPHA) or shared.fit.verdict["fits"] is False
    if len(names) > 1 and (per_guide or (per_guide is None and misfit and shared.n >= len(names) + 1)):
        say(f"fitting one stiffness per guide from {shared.values['k_rot']:.4g} N*m/rad/m")
        pg_model = SpringModel(board, tests, guides.spring_groups(board, True), bounds, sigma, noise,
                               result.mesh_pct, h, min_mac)
        result.per_guide = pg_model.fit(np.full(len(names), shared.values["k_rot"]), max_iter, say)
        pg = result.per_guide
        if pg.n < len(names) + 1:
            raise _too_few(pg.n, len(names) + 1, "one stiffness per guide", result.clamped)
        result.tests["per_guide_vs_shared"] = _per_guide_vs_shared(model, shared, pg, len(names))
        if per_guide or result.tests["per_guide_vs_shared"]["significant"]:
            result.chosen = pg
    fit = result.chosen
    common = _common(result.clamped_state(), fit.after)
    c_clamped, n = chi2([c["pairs"] for c in result.clamped.configs], sigma, common)
    test = significance(c_clamped, chi2([s["pairs"] for s in fit.after], sigma, common)[0], n,
                        len(fit.groups), len(fit.groups))
    result.tests["springs_vs_clamped"] = test
    if test["significant"]:
        result.decision = "springs"
        result.reason = (f"springs explain the test significantly better than clamped guides (F = {test['F']:.3g} > "
                         f"{test['critical']:.3g}, p = {test['p_value']:.2g}): max |df| "
                         f"{result.clamped.max_abs_freq_error_pct:.2f} % clamped, "
                         f"{fit.max_freq_error_pct:.2f} % with springs")
    else:
        result.decision = "clamped"
        what = f"F = {test['F']:.3g} < {test['critical']:.3g}, p = {test['p_value']:.2g}" if test["F"] is not None \
            else "no degree of freedom left to judge them"
        result.reason = (f"the clamped guides miss the tolerance (max |df| "
                         f"{result.clamped.max_abs_freq_error_pct:.2f} %), but springs do not explain the test "
                         f"significantly better ({what}): the rest of the error is not the guides' (as the thesis "
                         "concludes for its card, section 7.4.2); look elsewhere in the model (pcbdyn diagnose)")


def _per_guide_vs_shared(model, shared, pg, n_guides: int) -> dict:
    """The F test of one stiffness per guide against one shared (:func:`.spring_fit.significance`): on the
    per-guide fit's own objective when the shapes joined it (the shared stiffness on every guide is that
    model too; the frequencies of a nearly symmetric card barely tell the two apart), else on the frequencies
    of the modes paired in both."""
    if pg.fit.shapes:
        chi2_shared = evaluate(pg.fit.configs, np.full(n_guides, shared.values["k_rot"]))[1]
        v = pg.fit.verdict
        return significance(chi2_shared, v["chi2"], v["dof"] + n_guides, n_guides - 1, n_guides)
    common = _common(shared.after, pg.after)
    return significance(model.chi2(shared.after, common)[0], model.chi2(pg.after, common)[0],
                        sum(map(len, common)), n_guides - 1, n_guides)


def _common(a, b) -> list:
    """Per configuration the test modes paired in both correlation states."""
    return [{q["test_mode"] for q in x["pairs"]} & {q["test_mode"] for q in y["pairs"]} for x, y in zip(a, b)]
