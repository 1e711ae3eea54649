"""Iterative sensitivity-based updating of configurations (thesis eqs. 4.49-4.52, 7.2-7.6) inside a trust
region.

Every iteration solves the stacked equations of :func:`.iteration.build_equations` for relative changes
x = dp/p (or d ln p on a log scale) and tries p <- p (1 + x). A trial is kept only when it lowers the
objective (:func:`.iteration.objective_rows`: the paired frequency errors in units of their noise, with
the shapes' for "modal"), a trial that pairs fewer measured modes never being better. A rejected trial
shrinks the region (the largest |x| allowed) to a quarter of its step; a kept one that reached the
region's edge doubles it. The first step is the thesis' full step, so a fit whose linearisation holds
runs as the thesis runs it; one that starts far off (tens of percent, decades) moves as far as the
linearisation is trusted instead of overshooting into a worse model. The objective never rises, so there
is no divergence: a fit stops converged (eqs. 7.2-7.4, or at a minimum: the full step would gain less
than :data:`MIN_GAIN`), at the iteration limit, or stalled where no step however short lowers the
objective. The FRF methods' equation errors are no objective of that kind: their steps are all kept and
the iterate of least ||b|| returned.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .iteration import Configuration, _state, build_equations, objective_rows, unpaired
from .pbc import condition_number
from .solvers import SOLVERS, Solution, bayes_alpha, line_search

#: a rejected trial shrinks the trust region to this fraction of its step
SHRINK = 0.25
#: rejected trials in a row after which a fit has stalled (the last step is 0.25^8 ~ 1.5e-5 of the first)
MAX_REJECTED = 8
#: a fit whose full step would lower chi^2 (rows in units of their noise) by less than this is at its
#: minimum: no step of that size is significant (without noise units: this fraction of ||b||^2, 1e-6)
MIN_GAIN = 0.1


@dataclass
class UpdateResult:
    """Outcome of :func:`update`: the final parameters (the best state: the objective never rises), the
    kept iterates' history, ``stalled`` when no step lowered the objective any more although the
    equations asked for one, and the last solve's ``solution``."""

    p: np.ndarray
    converged: bool
    stalled: bool
    reason: str
    iterations: int
    best_iteration: int
    history: list = field(default_factory=list)
    solution: Solution | None = None


def evaluate(configs, p, pairing=None) -> tuple:
    """(unpaired measured modes, objective) of ``configs`` at ``p``: the sum of squares of
    :func:`.iteration.objective_rows`, or None where the model cannot be solved there. Without measured
    frequencies the objective is given by the caller (||b||)."""
    try:
        states = [_state(c, p, pairing) for c in configs]
    except (np.linalg.LinAlgError, ValueError, ArithmeticError):
        return None
    return _key(configs, states)


def _key(configs, states) -> tuple:
    rows = [objective_rows(c, st) for c, st in zip(configs, states)]
    if any(r is None for r in rows):
        return 0, None
    return sum(unpaired(c, st) for c, st in zip(configs, states)), float(sum(r @ r for r in rows))


def _better(a, b) -> bool:
    """Key ``a`` (unpaired, objective) is better than ``b``: fewer modes unpaired, else a lower objective."""
    return a[0] < b[0] or (a[0] == b[0] and a[1] < b[1] * (1.0 - 1e-12))


def update(
    configs, p0, *, solver: str = "ls", bounds=None, fixed=(), log_scale=(), pairing: Callable | None = None,
    max_iter: int = 30, use_line_search: bool | None = None, stack_reduce: bool = False,
    tol_freq_pct: float = 1.0, tol_param_pct: float = 0.5, tol_sigma_pct: float = 0.01,
    solver_options: dict | None = None, progress: Callable | None = None,
) -> UpdateResult:
    """Iterate sensitivity-based updating until convergence (module docstring).

    configs: one :class:`~.iteration.Configuration` or a list (PBC). p0: initial parameter values
    (non-zero). solver: "ls", "tls", "bayes" (alpha 0.5 * 0.9^iter, eq. 4.40) or "bounded" (needs
    ``bounds`` = (lower, upper) arrays of parameter values; the trust region is a box within them).
    fixed: indices of parameters held. log_scale: indices of parameters updated on a log scale,
    p <- p exp(x) (same first-order equations, since dp/p = d ln p; keeps stiffnesses that span decades
    positive). pairing: callable (f_a, phi_a_measured, f_x, phi_x) -> analytical index per measured mode,
    -1 for a mode left unpaired, for configurations that do not carry their own. use_line_search: minimise
    the overall frequency residue along the step (eq. 7.6; default on for "bayes"). Converged when one
    of: max frequency error < ``tol_freq_pct`` (7.2), a full step (not cut by the trust region) with every
    |x| < ``tol_param_pct`` (7.3), mean change of the frequency residue over the last three full steps
    < ``tol_sigma_pct`` (7.4). solver_options: keyword arguments of the "ls"/"tls" solver, or
    alpha0/factor of the Bayesian schedule. Each history entry holds p, the objective and the unpaired
    modes, the frequency residue, max frequency error, ||b||, pairs, MAC of the pairs, condition numbers
    per configuration and stacked, the rank, message and step of the solve made from it and the trials
    rejected before it; ``progress(entry)`` is called with each kept entry.
    """
    configs = [configs] if isinstance(configs, Configuration) else list(configs)
    if solver not in SOLVERS:
        raise ValueError(f"solver={solver!r}; choose one of {sorted(SOLVERS)}")
    p = np.asarray(p0, float).copy()
    if np.any(p == 0):
        raise ValueError("p0: relative design variables (eq. 4.41) need non-zero parameter values")
    free = np.setdiff1d(np.arange(p.size), np.asarray(fixed, int))
    is_log = np.zeros(p.size, bool)
    is_log[np.asarray(log_scale, int)] = True

    def stepped(q, dx):
        return np.where(is_log, q * np.exp(dx), q * (1 + dx))

    def rel_bound(v, q):
        with np.errstate(divide="ignore"):
            return np.where(is_log, np.log(v / q), v / q - 1)

    if solver == "bounded":
        if bounds is None:
            raise ValueError("solver 'bounded' needs bounds=(lower, upper) parameter values")
        lo, hi = (np.broadcast_to(np.asarray(v, float), p.shape) for v in bounds)
    line = (solver == "bayes") if use_line_search is None else use_line_search
    have_f = all(c.f_x is not None for c in configs)
    noise_units = have_f and all(c.sigma is not None or c.method == "modal" for c in configs)
    opts = dict(solver_options or {})

    def state_at(q, it):
        """The history entry and equations at ``q``; None where the model cannot be solved."""
        try:
            (A, b), blocks, states = build_equations(configs, q, pairing, stack_reduce)
        except (np.linalg.LinAlgError, ValueError, ArithmeticError):
            if it == 0:
                raise
            return None
        raw_norm = float(np.linalg.norm(np.concatenate([blk.b for blk in blocks])))
        paired = [st for st in states if not st.get("set_aside")]
        key = _key(configs, states)
        key = (key[0], raw_norm**2 if key[1] is None else key[1])
        entry = {
            "iteration": it, "p": q.copy(), "objective": key[1], "unpaired": key[0],
            "sigma": float(np.sqrt(np.mean([st["sigma"] ** 2 for st in paired]))) if have_f else None,
            "residual_norm": raw_norm,
            "max_freq_error_pct": max(st["max_err_pct"] for st in paired) if have_f else None,
            "pairs": [st.get("pairs") for st in states], "mac": [st.get("mac") for st in states],
            "set_aside": [c.name for c, st in zip(configs, states) if st.get("set_aside")],
            "condition_per_configuration": [condition_number(blk.A[:, free]) for blk in blocks],
            "condition_stacked": condition_number(A[:, free]), "rejected": 0,
        }
        return entry, A[:, free], b, key

    def solve(it, radius):
        if solver == "bayes":
            return SOLVERS[solver](A, b, alpha=bayes_alpha(it, opts.get("alpha0", 0.5), opts.get("factor", 0.9)))
        if solver == "bounded":
            return SOLVERS[solver](A, b, np.maximum(rel_bound(lo, p)[free], -radius),
                                   np.minimum(rel_bound(hi, p)[free], radius))
        return SOLVERS[solver](A, b, **opts)

    def residue(q):
        states = [_state(c, q, pairing) for c in configs]
        return float(np.sqrt(np.mean([st["sigma"] ** 2 for st in states if not st.get("set_aside")])))

    entry, A, b, key = state_at(p, 0)
    history, radius, full_steps, last_sol = [entry], np.inf, [], None
    if progress is not None:
        progress(entry)
    converged, stalled, reason = False, False, "maximum number of iterations reached"
    while True:
        it = len(history) - 1
        if have_f and entry["max_freq_error_pct"] < tol_freq_pct:
            converged = True
            reason = f"max frequency error {entry['max_freq_error_pct']:.3g} % < {tol_freq_pct} % (eq. 7.2)"
            break
        if it >= 1 and full_steps[-1] and np.max(np.abs(history[-2]["proposed"])) * 100 < tol_param_pct:
            converged, reason = True, f"max parameter change < {tol_param_pct} % (eq. 7.3)"
            break
        if have_f and it >= 3 and all(full_steps[-3:]):
            s = [h["sigma"] for h in history[-4:]]
            if np.mean(np.abs(np.diff(s))) * 100 < tol_sigma_pct:
                converged = True
                reason = f"frequency residue changed < {tol_sigma_pct} % over three iterations (eq. 7.4)"
                break
        if it == max_iter:
            break
        trial, rejected, first, searched = None, 0, None, False
        while trial is None and rejected < MAX_REJECTED:
            sol = solve(it, np.inf if first is None else radius)
            if first is None and solver == "bounded" and np.max(np.abs(sol.x), initial=0.0) > radius:
                first = _first(sol, A, b, True)
                sol = solve(it, radius)
            last_sol = sol
            x = np.zeros(p.size)
            x[free] = sol.x
            size = float(np.max(np.abs(x))) if x.size else 0.0
            cut = size > radius * (1 - 1e-9)
            first = _first(sol, A, b, cut) if first is None else first
            if size == 0.0:
                break
            if cut and solver != "bounded":
                x *= radius / size
            beta = 1.0
            if line and have_f:
                beta = line_search(lambda bt: _safe(residue, stepped(p, bt * x)))[0]
                searched = beta == 0.0
                if searched:
                    break
            candidate = state_at(stepped(p, beta * x), it + 1)
            if candidate is not None and (not have_f or _better(candidate[3], key)):
                trial = candidate
            else:
                rejected += 1
                radius = SHRINK * beta * min(size, radius)
        entry.update(rank=sol.rank, rank_deficient=sol.rank_deficient, message=sol.message)
        if trial is None:
            if not first[1] and first[0] * 100 < tol_param_pct:
                converged, reason = True, f"max parameter change < {tol_param_pct} % (eq. 7.3)"
            elif first[2] < (MIN_GAIN if noise_units else 1e-6 * float(b @ b)):  # the full step's gain
                converged = True
                reason = f"at a minimum: the full step would lower the objective by only {first[2]:.2g}"
            elif searched:
                stalled = True
                reason = ("stalled: the line search (eq. 7.6) found no decrease of the frequency residue at "
                          f"iteration {it}")
            else:
                stalled = True
                reason = (f"stalled at iteration {it}: no step along the equations' solution lowers the objective "
                          f"(the shortest tried moved a parameter by {100 * size:.3g} %)")
            break
        entry.update(step=beta * x, proposed=x, beta=beta)
        if cut:
            radius = 2.0 * radius
        full_steps.append(not cut and rejected == 0)
        entry, A, b, key = trial
        entry["rejected"] = rejected
        p = entry["p"]
        history.append(entry)
        if progress is not None:
            progress(entry)
    final = len(history) - 1
    if not (have_f or converged):  # equation errors without an objective of their own: the least ||b||
        final = int(np.argmin([h["residual_norm"] for h in history]))
    return UpdateResult(history[final]["p"], converged, stalled, reason, final, final, history, last_sol)


def _first(sol, A, b, cut) -> tuple:
    """(largest |x|, cut by the trust region, the fall of ||b||^2 it predicts) of the full step ``sol``."""
    return float(np.max(np.abs(sol.x), initial=0.0)), cut, float(b @ b - np.sum((b - A @ sol.x) ** 2))


def _safe(residue, q) -> float:
    try:
        return residue(q)
    except (np.linalg.LinAlgError, ValueError, ArithmeticError):
        return np.inf  # the trial model cannot be solved: not a candidate


def at_bounds(names, p, bounds) -> dict:
    """{name: "lower" | "upper"} of the parameters ``p`` that stopped on a side of ``bounds`` = (lower,
    upper; the physical range of thesis section 4.8): a parameter held there is not fitted by the data,
    and is often pulled there by what the model lacks."""
    lo, hi = bounds
    return {n: "lower" if np.isclose(v, a, rtol=1e-6) else "upper" for n, v, a, b in zip(names, p, lo, hi)
            if np.isclose(v, a, rtol=1e-6) or np.isclose(v, b, rtol=1e-6)}
