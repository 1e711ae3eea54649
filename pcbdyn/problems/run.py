"""Running an update of an :class:`~.problem.UpdateProblem`, the correlation before and after it, and
what happened in the user's terms (status, parameters on their bounds, configurations made worse,
parameter combinations the data do not determine)."""

from __future__ import annotations

import warnings

import numpy as np

from ..updating.driver import at_bounds, update
from ..updating.iteration import paired_states
from ..updating.solvers import RankDeficiencyWarning

#: the frequency criterion (thesis eq. 7.2, max |df| in %) an update stops at unless told otherwise: the
#: API's and ``pcbdyn update --tol``'s (tests/docs/test_readme_api.py keeps them one)
TOL_FREQ_PCT = 0.1


def correlation_state(configs, p) -> list:
    """Per configuration at ``p``: the pairs (as in ``pcbdyn correlate``: test_mode, model_mode
    (1-based, elastic modes), f_test_hz, f_model_hz, df_pct, mac), the max |df| in percent (None for
    a configuration none of whose modes pairs; also when none of any configuration's pairs: a test of
    another structure is reported, not refused), the pairing's warnings (model modes the test grid
    cannot tell apart, pairs beyond the frequency limit: reported, not used) and the groups of test modes
    compared as a plane (``close_test_modes``, :mod:`pcbdyn.correlation.close_modes`; their MACs are
    after the turn)."""
    states = paired_states(configs, p)
    out = []
    for cfg, st in zip(configs, states):
        pairs = []
        for k, (u, fa) in enumerate(zip(st["used"], st.get("f_a", []))):
            ft = float(cfg.f_x[u])
            pairs.append({"test_mode": int(u) + 1, "model_mode": int(st["pairs"][u]) + 1 - cfg.n_rigid,
                          "f_test_hz": ft, "f_model_hz": float(fa), "df_pct": 100.0 * (float(fa) - ft) / ft,
                          "mac": None if st.get("mac") is None else float(st["mac"][k])})
        said = getattr(cfg.pairing, "warnings", None)
        out.append({"configuration": cfg.name, "pairs": pairs,
                    "max_freq_error_pct": max(abs(q["df_pct"]) for q in pairs) if pairs else None,
                    "warnings": said() if said else []})
        if st.get("close"):
            out[-1]["close_test_modes"] = [[int(st["used"][a]) + 1 for a in g] for g in st["close"]]
    return out


def run(problem, configs, solver: str = "ls", check=None, **kwargs):
    """Update ``problem``'s parameters against ``configs`` (its bounds and log scale filled in); returns
    (UpdateResult, before, after), before/after from :func:`correlation_state` on ``check`` (default
    ``configs``; give the full-model configurations of :meth:`~.problem.UpdateProblem.configuration`
    when updating on :meth:`~.problem.UpdateProblem.mode_configurations`). ``kwargs`` go to
    :func:`pcbdyn.updating.driver.update` (``progress``, ``max_iter``, ``tol_freq_pct``: default
    :data:`TOL_FREQ_PCT`, as the command line's, ...). The solvers' warnings
    are not printed: :func:`outcome` says what they meant with the parameters named."""
    check = configs if check is None else check
    kwargs.setdefault("tol_freq_pct", TOL_FREQ_PCT)
    before = correlation_state(check, problem.p0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RankDeficiencyWarning)
        res = update(configs, problem.p0, solver=solver, bounds=problem.bounds, log_scale=problem.log_scale, **kwargs)
    after = correlation_state(check, res.p)
    return res, before, after


def _combination(v, names) -> str:
    big = np.argsort(-np.abs(v))[:4]
    big = big[np.abs(v[big]) > 0.1 * np.abs(v).max()]
    return " and ".join(f"{names[i]} ({'+' if v[i] * v[big[0]] > 0 else '-'})" for i in big)


def undetermined_directions(vectors, names) -> list:
    """Each parameter direction of ``vectors`` in words: its main parameters with the sign each moves with
    ("k_top (+) and k_bottom (-)": one up and the other down leaves the data as they are)."""
    return [f"{_combination(np.asarray(v, float), names)}" + (" separately" if len(names) > 1 else "")
            for v in vectors]


def worse_configurations(before, after) -> list:
    """[(configuration, max |df| before, after)] of the configurations whose error grew."""
    return [(b["configuration"], b["max_freq_error_pct"], a["max_freq_error_pct"]) for b, a in zip(before, after)
            if None not in (b["max_freq_error_pct"], a["max_freq_error_pct"])
            and a["max_freq_error_pct"] > b["max_freq_error_pct"] * (1 + 1e-9)]


def outcome(problem, res, before, after) -> dict:
    """What an update did, in the user's terms: ``status`` ("error grew", "on a bound", "not determined",
    "stalled", "not converged" or "converged": the first that applies), and ``details``: parameters at
    their bounds, configurations whose error grew (before -> after), parameter combinations the equations
    did not determine at the last solve, configurations set aside because no mode paired; ``warnings``:
    the pairing's before and after (:func:`pairing_warnings`). The fits of :func:`.fit.fit` judge more
    (the chi^2 verdict, the directions in units of the noise)."""
    bounds = at_bounds(problem.names, res.p, problem.bounds)
    worse = worse_configurations(before, after)
    sol = res.solution
    undetermined = [] if sol is None or not sol.rank_deficient else undetermined_directions(
        sol.null_space.T[:3], problem.names)
    set_aside = sorted({n for h in res.history for n in h.get("set_aside", [])})
    details = [f"{n} stopped at its {side} bound" for n, side in bounds.items()]
    details += [f"configuration {c}: max |df| grew from {b:.2f} % to {a:.2f} %" for c, b, a in worse]
    details += [f"the data do not determine {c} (rank-deficient equations)" for c in undetermined]
    details += [f"configuration {c}: no mode paired at some iteration; set aside there" for c in set_aside]
    if worse:
        status = "error grew"
    elif bounds:
        status = "on a bound"
    elif undetermined:
        status = "not determined"
    elif res.stalled:
        status = "stalled"
    else:
        status = "converged" if res.converged else "not converged"
    return {"status": status, "details": details, "at_bounds": bounds, "worse": [c for c, _, _ in worse],
            "undetermined": undetermined, "set_aside": set_aside, "warnings": pairing_warnings(before + after)}


def pairing_warnings(states) -> list:
    """The pairing's warnings of correlation ``states`` (model modes the test grid cannot tell apart, pairs
    beyond the frequency limit), each once, prefixed with its configuration."""
    return list(dict.fromkeys(f"configuration {s['configuration']}: {w}" for s in states
                              for w in s.get("warnings", [])))
