"""The verdict on a finished fit of :mod:`.fit` (its module docstring, step 5): chi^2 against the degrees
of freedom the noise allows (eq. 4.28), the share of measured modes paired, bounds reached, the parameter
directions the data leave open, and the status and sentences that say so."""

from __future__ import annotations

import numpy as np

from ..units import from_si
from ..updating.driver import at_bounds
from ..updating.iteration import build_equations, objective_rows, unpaired
from ..updating.solvers import choose_rank
from .error_budget import noise_probability
from .run import undetermined_directions, worse_configurations

#: chi^2 with a smaller probability than this under the noise: the model cannot fit the test
ALPHA_FIT = 1e-3
#: a fit that pairs fewer of the measured modes than this share cannot fit the test, whatever its chi^2
MIN_PAIRED = 0.5
#: a parameter direction x = dp/p (d ln p on a log scale) known no better than this at one sigma is not
#: determined by the data
UNDETERMINED_SD = 0.5


def weak_directions(configs, p, names, free=None) -> list:
    """The parameter directions the equations of ``configs`` (rows in noise units) at ``p`` do not
    determine: numerically rank-deficient, or known no better than :data:`UNDETERMINED_SD` at one sigma."""
    (A, _), _, _ = build_equations(configs, p)
    free = np.arange(A.shape[1]) if free is None else np.asarray(free)
    _, s, Vt = np.linalg.svd(A[:, free], full_matrices=False)
    rank = choose_rank(s, jump=np.inf) if s.size else 0  # rows in noise units: sizes, not jumps, decide
    weak = [Vt[i] for i in range(s.size) if i >= rank or s[i] < 1.0 / UNDETERMINED_SD]
    return undetermined_directions(weak, [names[j] for j in free])


def verdict(cfgs, p, problem) -> dict:
    """chi^2 of the fit's objective at ``p`` against its degrees of freedom (rows less the free parameters
    and, for shapes, one scale factor per mode)."""
    (_, _), _, states = build_equations(cfgs, p)
    rows = [objective_rows(c, st) for c, st in zip(cfgs, states)]
    if any(r is None for r in rows):
        return {"chi2": None, "dof": None, "p_value": None, "fits": None}
    chi2 = float(sum(r @ r for r in rows))
    scales = sum(np.size(st["used"]) for c, st in zip(cfgs, states) if c.method == "modal")
    dof = int(sum(r.size for r in rows) - len(problem.names) - scales)
    pv = noise_probability(chi2, dof) if dof > 0 else None
    measured = sum(np.size(c.f_x) for c in cfgs)
    paired = measured - sum(unpaired(c, st) for c, st in zip(cfgs, states))
    fits = None if pv is None else bool(pv >= ALPHA_FIT)
    if paired < MIN_PAIRED * measured:
        fits = False  # the test's modes are not the model's
    return {"chi2": chi2, "dof": dof, "p_value": pv, "fits": fits, "paired_modes": int(paired),
            "measured_modes": int(measured)}


def judge(out, cfgs) -> None:
    """``status`` and ``details`` of a finished :class:`.fit.Fit` (:mod:`.fit`'s docstring, step 5); the
    directions the data leave open from ``cfgs``, rows in noise units (None: from the rank of the last
    solve, for QMS and FBM)."""
    prob, res = out.problem, out.result
    out.at_bounds = at_bounds(prob.names, out.p, prob.bounds)
    out.worse = worse_configurations(out.before, out.after)
    free = [j for j, n in enumerate(prob.names) if n not in out.at_bounds]
    if cfgs is None:
        sol = res.solution
        out.undetermined = [] if sol is None or not sol.rank_deficient else undetermined_directions(
            sol.null_space.T[:3], prob.names)
    else:
        out.undetermined = weak_directions(cfgs, out.p, prob.names, free) if free else []
    v = out.verdict
    noise = f"frequency noise {out.noise['frequency_pct']:g} %" + (
        f", shape noise {out.noise['shape_pct']:g} %" if out.noise["shape_pct"] is not None else "")
    if out.noise["shape_estimated"]:
        noise += " (the shapes' estimated from their residual)"
    if not out.noise["stated"][0]:
        noise += " (the frequencies' assumed; state it with --noise)"
    d = []
    if v["chi2"] is not None:
        model = ", and the model error" if out.noise["model_error"] else ""
        chi2 = (f"chi^2 {v['chi2']:.4g} over {v['dof']} degrees of freedom (probability {v['p_value']:.2g} under the "
                f"{noise}{model})" if v["p_value"] is not None else
                f"chi^2 {v['chi2']:.4g} with no degree of freedom left to judge it (fewer rows than parameters)")
        if v["paired_modes"] < MIN_PAIRED * v["measured_modes"]:
            d.append(f"the model cannot fit the test: only {v['paired_modes']} of its {v['measured_modes']} measured "
                     f"modes pair with a model mode (a test of another structure or configuration?); {chi2}")
        elif v["fits"] is False:
            d.append(f"the model cannot fit the test: {chi2}")
        else:
            d.append(f"{chi2}: within the noise" if v["fits"] else chi2)
    d += [f"configuration {c}: max |df| grew from {b:.2f} % to {a:.2f} %" for c, b, a in out.worse]
    d += [f"{n} stopped at its {side} bound" for n, side in out.at_bounds.items()]
    d += [f"the data do not determine {c}" for c in out.undetermined]
    if out.shapes:
        d.append(f"mode shapes in the objective: {out.shapes}")
    d += [f"another start ended worse: {values_text(prob, s['end'])} (chi^2 {s['objective']:.4g})"
          for s in out.starts if not s["kept"] and not np.allclose(s["end"], out.p, rtol=1e-2)]
    if v["fits"] is False:
        status = "cannot fit"
    elif out.worse:
        status = "error grew"
    elif out.at_bounds:
        status = "on a bound"
    elif out.undetermined:
        status = "not determined"
    else:
        status = "converged" if res.converged else "not converged"
    out.status, out.details = status, d + [f"fit: {res.reason}"]


def values_text(problem, p) -> str:
    """The parameters ``p`` in the problem's units, for messages."""
    return ", ".join(f"{n} {from_si(v, u):.4g} {u}" for (n, v), u in zip(problem.values(p).items(), problem.units))
