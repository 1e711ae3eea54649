"""Running an update of an :class:`~.problem.UpdateProblem` and the correlation before and after it."""

from __future__ import annotations

from ..updating.iteration import build_equations, update


def correlation_state(configs, p) -> list:
    """Per configuration at ``p``: the pairs (as in ``pcbdyn correlate``: test_mode, model_mode
    (1-based, elastic modes), f_test_hz, f_model_hz, df_pct, mac) and the max |df| in percent."""
    _, _, states = build_equations(configs, p)
    out = []
    for cfg, st in zip(configs, states):
        pairs = []
        for k, (u, fa) in enumerate(zip(st["used"], st["f_a"])):
            ft = float(cfg.f_x[u])
            pairs.append({"test_mode": int(u) + 1, "model_mode": int(st["pairs"][u]) + 1 - cfg.n_rigid,
                          "f_test_hz": ft, "f_model_hz": float(fa), "df_pct": 100.0 * (float(fa) - ft) / ft,
                          "mac": None if st.get("mac") is None else float(st["mac"][k])})
        out.append({"configuration": cfg.name, "pairs": pairs,
                    "max_freq_error_pct": max(abs(q["df_pct"]) for q in pairs)})
    return out


def run(problem, configs, solver: str = "ls", check=None, **kwargs):
    """Update ``problem``'s parameters against ``configs`` (its bounds and log scale filled in); returns
    (UpdateResult, before, after), before/after from :func:`correlation_state` on ``check`` (default
    ``configs``; give the full-model configurations of :meth:`~.problem.UpdateProblem.configuration`
    when updating on :meth:`~.problem.UpdateProblem.mode_configurations`). ``kwargs`` go to
    :func:`pcbdyn.updating.iteration.update`."""
    check = configs if check is None else check
    before = correlation_state(check, problem.p0)
    res = update(configs, problem.p0, solver=solver, bounds=problem.bounds, log_scale=problem.log_scale, **kwargs)
    after = correlation_state(check, res.p)
    return res, before, after
