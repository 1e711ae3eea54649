"""Iterative sensitivity-based updating on plain callables (thesis section 4.9, 7.3.1, chapter 6).

A configuration is a model callable ``p -> (K, M, dKs, dMs)`` plus its measured data. Every
iteration re-solves each configuration, re-pairs its modes (by MAC when shapes are measured,
through a ``pairing`` callable), builds its weighted equations, stacks all configurations
(PBC, eq. 6.4), solves for relative changes x = dp/p and updates p <- p (1 + beta x)
(eqs. 4.49-4.52). It stops on the criteria of eqs. 7.2-7.4, and on divergence, keeping the best
iterate.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from . import equations as eq
from . import matching
from .errors import UpdatingError
from .pbc import condition_number, stack
from .sensitivity import frequencies_hz, solve_modes
from .solvers import SOLVERS, Solution, bayes_alpha, frequency_residue, line_search
from .weighting import std_row_weights, unit_row_weights, weight_rows

METHODS = ("freq", "freq-rel", "fbm", "qms", "frf-in", "frf-out", "frf-direct")


@dataclass
class Configuration:
    """One test configuration (the main one or a perturbed one).

    model: p -> (K, M, dKs, dMs), the matrices and their parameter derivatives at p.
    f_x: measured natural frequencies [Hz] (frequency equations, pairing and convergence).
    phi_x: measured shapes (n_meas, n_modes) on the measured DOFs, one column per f_x.
    P: (n_meas, n_dof) maps model DOFs to measured DOFs (None: every DOF measured).
    frf_omegas, H_x, excitation: updating frequencies [rad/s], measured receptances
        (n_meas, n_freq) and the excited model DOF for the FRF methods.
    method: one of METHODS. matching: "expand" (dynamic expansion of the data) or "reduce"
        (Guyan reduction of the model) when P is not None. damping: treatment of unknown damping
        in the data (appendix A): any of equations.DAMPING_TREATMENTS for "frf-in",
        "undamped"/"proportional" for "frf-out".
    sigma: standard deviations of the equations' rows (chi-squares weights, eq. 4.28);
        None gives unit-length rows (eq. 4.42).
    n_modes: analytical modes computed for pairing (default max(2 m, m + 4) for m measured
        modes; count the rigid-body modes of a free model in).
    pairing: callable (f_a, phi_a_measured, f_x, phi_x) -> analytical mode index per measured mode,
        -1 for a mode left unpaired (default: the driver's ``pairing``, else :func:`mac_pairing`).
    n_rigid: rigid-body modes among the analytical ones (a free model's; they never pair).
    frf_hz: the updating frequencies [Hz] of the FRF methods (``frf_omegas`` in Hz, for reports).
    """

    model: Callable
    f_x: np.ndarray | None = None
    phi_x: np.ndarray | None = None
    P: object = None
    frf_omegas: np.ndarray | None = None
    H_x: np.ndarray | None = None
    excitation: int | None = None
    method: str = "freq"
    matching: str = "expand"
    damping: str = "undamped"
    n_exclude: int = 1
    sigma: np.ndarray | None = None
    n_modes: int | None = None
    name: str = ""
    pairing: Callable | None = None
    n_rigid: int = 0

    @property
    def frf_hz(self) -> np.ndarray | None:
        return None if self.frf_omegas is None else np.asarray(self.frf_omegas, float) / (2 * np.pi)

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"method={self.method!r}; choose one of {METHODS}")
        if self.method.startswith("freq") and self.f_x is None:
            raise ValueError(f"configuration {self.name!r}: method {self.method!r} needs f_x (measured frequencies)")
        if self.method in ("fbm", "qms") and (self.phi_x is None or self.f_x is None):
            raise ValueError(f"configuration {self.name!r}: method {self.method!r} needs f_x and phi_x")
        if self.method.startswith("frf") and (self.H_x is None or self.frf_omegas is None or self.excitation is None):
            raise ValueError(f"configuration {self.name!r}: method {self.method!r} needs frf_omegas, H_x and excitation")
        if self.matching not in ("expand", "reduce"):
            raise ValueError(f"matching={self.matching!r}; choose 'expand' or 'reduce'")


def mac_matrix(a, b) -> np.ndarray:
    """MAC between the columns of a and b (real or complex)."""
    num = np.abs(a.conj().T @ b) ** 2
    return num / np.outer(np.einsum("ij,ij->j", a.conj(), a).real, np.einsum("ij,ij->j", b.conj(), b).real)


def mac_pairing(f_a, phi_a, f_x, phi_x) -> np.ndarray:
    """Analytical mode index for each measured mode: largest MAC, ties broken by the closest
    frequency, each analytical mode used once (greedy on decreasing MAC). Without shapes: by
    closest frequency. Pass pcbdyn.correlation's pairing instead when available."""
    f_a, f_x = np.asarray(f_a), np.asarray(f_x)
    if phi_x is None:
        score = -np.abs(f_a[:, None] / f_x[None, :] - 1)
    else:
        score = mac_matrix(phi_a, phi_x) - 1e-6 * np.abs(f_a[:, None] / f_x[None, :] - 1)
    pairs = -np.ones(f_x.size, int)
    S = score.copy()
    for _ in range(min(S.shape)):
        i, k = np.unravel_index(np.argmax(S), S.shape)
        pairs[k] = i
        S[i, :] = -np.inf
        S[:, k] = -np.inf
    return pairs


@dataclass
class UpdateResult:
    """Outcome of :func:`update`: final (best) parameters and the full history."""

    p: np.ndarray
    converged: bool
    diverged: bool
    reason: str
    iterations: int
    best_iteration: int
    history: list = field(default_factory=list)
    solution: Solution | None = None


def _state(cfg: Configuration, p, pairing):
    """Model matrices, paired modes and residue of one configuration at p."""
    K, M, dKs, dMs = cfg.model(p)
    out = {"K": K, "M": M, "dKs": dKs, "dMs": dMs}
    if cfg.f_x is not None:
        f_x = np.asarray(cfg.f_x, float)
        n_modes = cfg.n_modes or min(K.shape[0], max(2 * f_x.size, f_x.size + 4))
        lam, Phi = solve_modes(K, M, n_modes)
        f_a = frequencies_hz(lam)
        phi_am = Phi if cfg.P is None else np.asarray(cfg.P @ Phi)
        pairs = np.asarray((cfg.pairing or pairing or mac_pairing)(f_a, phi_am, f_x, cfg.phi_x), int)
        used = np.flatnonzero(pairs >= 0)
        if used.size == 0:  # set aside at this state: nothing of it pairs
            out.update(set_aside=True, pairs=pairs, used=used)
            return out
        ia = pairs[used]
        out.update(lam=lam[ia], Phi=Phi[:, ia], f_a=f_a[ia], pairs=pairs, used=used,
                   sigma=frequency_residue(f_a[ia], f_x[used]),
                   max_err_pct=float(np.max(np.abs(1 - f_a[ia] / f_x[used])) * 100))
        if cfg.phi_x is not None:
            out["mac"] = np.diag(mac_matrix(phi_am[:, ia], np.asarray(cfg.phi_x)[:, used]))
    return out


def _block(cfg: Configuration, st, p) -> eq.Block:
    K, M, dKs, dMs = st["K"], st["M"], st["dKs"], st["dMs"]
    used = st.get("used")
    if cfg.method in ("freq", "freq-rel"):
        f_x = np.asarray(cfg.f_x, float)[used]
        return eq.frequency_equations(st["lam"], st["Phi"], f_x, dKs, dMs, p, relative_rows=cfg.method == "freq-rel")
    if cfg.method == "frf-direct":
        return eq.frf_receptance_equations(K, M, cfg.frf_omegas, cfg.H_x, cfg.excitation, dKs, dMs, p, "direct", P=cfg.P)
    if _condensed(cfg):
        return _condensed_frf_equations(cfg, K, M, dKs, dMs, p)
    shapes = cfg.method in ("fbm", "qms")
    omegas = 2 * np.pi * np.asarray(cfg.f_x, float)[used] if shapes else np.asarray(cfg.frf_omegas, float)
    data = np.asarray(cfg.phi_x)[:, used] if shapes else np.asarray(cfg.H_x)
    j = cfg.excitation
    if cfg.P is not None:
        if cfg.matching == "reduce":
            K, M, dKs, dMs = matching.reduce_system(K, M, dKs, dMs, cfg.P)
            j = None if shapes else matching.measured_rows(cfg.P, cfg.excitation)
        else:
            data = matching.expand(K, M, cfg.P, data, omegas)
    if cfg.method == "fbm":
        return eq.fbm_equations(K, M, omegas, data, dKs, dMs, p)
    if cfg.method == "qms":
        return eq.qms_equations(K, M, omegas, data, dKs, dMs, p, n_exclude=cfg.n_exclude)
    if cfg.method == "frf-in":
        return eq.frf_excitation_equations(K, M, omegas, data, j, dKs, dMs, p, damping=cfg.damping)
    return eq.frf_receptance_equations(K, M, omegas, data, j, dKs, dMs, p, "indirect", damping=cfg.damping)


def _condensed(cfg) -> bool:
    return cfg.method in ("frf-in", "frf-out") and cfg.P is not None and cfg.matching == "expand"


def _condensed_frf_equations(cfg, K, M, dKs, dMs, p) -> eq.Block:
    """Eqs. 3.34 (frf-in) and 3.35 (frf-out) on the measured DOFs, the model condensed exactly at each
    updating frequency; frf-in rows weighted by the noise they carry (eq. 4.28).

    Expanding the data and keeping every model row would bias the input residual: the rows of the
    unmeasured DOFs have a zero right-hand side by construction of the expansion yet carry
    derivative terms, and a damping fit (appendix A) would be spread over them. Premultiplying the
    expanded equations by T(w)^T (T the dynamic map of eq. 2.25) removes them; it equals the
    equations of the dynamically condensed model Z_r = T^T Z T, exact at w. For frf-out this is the
    same as the expanded eq. 3.35 (Z_r^-1 T^T = P H_a) and lets the proportional-damping fit see only
    measured rows. The excitation must be a measured DOF (a driving-point FRF).

    frf-in: a relative error e in the data gives row i the standard deviation
    e (sum_k |Z_r,ik h_k|^2)^1/2; unit-length rows (eq. 4.42) would blow up the stiff, insensitive
    ones. Each frequency's weighted rows are scaled to unit mean length, so frequencies weigh alike."""
    j = matching.measured_rows(cfg.P, cfg.excitation)
    A_all, b_all = [], []
    for w, h in zip(np.asarray(cfg.frf_omegas, float), np.asarray(cfg.H_x).T):
        Kr, Mr, dKr, dMr = matching.reduce_system(K, M, dKs, dMs, cfg.P, omega=w)
        if cfg.method == "frf-out":
            A, b = eq.frf_receptance_equations(Kr, Mr, [w], h[:, None], j, dKr, dMr, p, "indirect",
                                               damping=cfg.damping)
        else:
            A, b = eq.frf_excitation_equations(Kr, Mr, [w], h[:, None], j, dKr, dMr, p, damping=cfg.damping)
            sigma = np.sqrt(np.abs(Kr - w**2 * Mr) ** 2 @ np.abs(h) ** 2)
            d = np.tile(1.0 / np.maximum(sigma, sigma.max() * 1e-12), A.shape[0] // sigma.size)
            d /= np.sqrt(np.mean(np.sum((d[:, None] * A) ** 2, axis=1)))
            A, b = d[:, None] * A, d * b
        A_all.append(A)
        b_all.append(b)
    return eq.Block(np.vstack(A_all), np.concatenate(b_all))


def _weighted(cfg, blk, st):
    """``blk`` with unit-length rows (eq. 4.42) or rows in units of ``cfg.sigma`` (eq. 4.28); a sigma per
    measured frequency keeps the rows of the modes paired in this state ``st``."""
    if cfg.sigma is None and cfg.method == "frf-in" and _condensed(cfg):
        return blk  # weighted by its noise already
    sigma = cfg.sigma
    if sigma is not None and cfg.method.startswith("freq") and np.size(sigma) == np.size(cfg.f_x):
        sigma = np.asarray(sigma, float)[st["used"]]
    d = unit_row_weights(blk.A) if sigma is None else std_row_weights(sigma)
    return eq.Block(*weight_rows(blk.A, blk.b, d))


def build_equations(configs, p, pairing: Callable | None = None, stack_reduce: bool = False):
    """Stacked, row-weighted equations of all configurations at p, columns weighted by p (x = dp/p).

    Returns (Block, blocks, states): the stacked block (eq. 6.4; SVD-reduced per configuration
    with ``stack_reduce``, eq. 6.6) for a solver or for localisation (:func:`~.subset.tls_qrf`),
    the unweighted block of each configuration that pairs, and each configuration's state (paired
    frequencies "f_a", "pairs", "mac", frequency residue "sigma", "max_err_pct"; "set_aside" for a
    configuration none of whose measured modes found a partner at p: it is left out of the equations
    there, as a mode without a partner is left out of its configuration's, and not an error).
    """
    configs = [configs] if isinstance(configs, Configuration) else list(configs)
    p = np.asarray(p, float)
    states = [_state(c, p, pairing) for c in configs]
    active = [(c, st) for c, st in zip(configs, states) if not st.get("set_aside")]
    if not active:
        raise UpdatingError("no measured mode of any configuration found an analytical partner; check that test and "
                         "model are the same structure and configuration, and the points' frame and units")
    blocks = [_block(c, st, p) for c, st in active]
    stacked = stack([_weighted(c, blk, st) for (c, st), blk in zip(active, blocks)], reduce=stack_reduce)
    return stacked, blocks, states


def update(
    configs, p0, *, solver: str = "ls", bounds=None, fixed=(), log_scale=(), pairing: Callable | None = None,
    max_iter: int = 30, use_line_search: bool | None = None, stack_reduce: bool = False,
    tol_freq_pct: float = 1.0, tol_param_pct: float = 0.5, tol_sigma_pct: float = 0.01,
    patience: int = 3, solver_options: dict | None = None, progress: Callable | None = None,
) -> UpdateResult:
    """Iterate sensitivity-based updating until convergence (thesis eqs. 4.49-4.52, 7.2-7.6).

    configs: one :class:`Configuration` or a list (PBC). p0: initial parameter values (non-zero).
    solver: "ls", "tls", "bayes" (alpha 0.5 * 0.9^iter, eq. 4.40) or "bounded" (needs ``bounds``
    = (lower, upper) arrays of parameter values). fixed: indices of parameters held.
    log_scale: indices of parameters updated on a log scale, p <- p exp(x) instead of p (1 + x)
    (same first-order equations, since dp/p = d ln p; keeps stiffnesses that span decades
    positive).
    pairing: callable (f_a, phi_a_measured, f_x, phi_x) -> analytical index per measured mode,
    -1 for a mode left unpaired (dropped from that iteration's equations), for configurations that
    do not carry their own (``Configuration.pairing``; default :func:`mac_pairing`). use_line_search: minimise the overall frequency residue along
    the step (eq. 7.6; default on for "bayes"). Stops when one of: max frequency error <
    ``tol_freq_pct`` (7.2), max parameter change < ``tol_param_pct`` (7.3), mean change of the
    frequency residue over the last three iterations < ``tol_sigma_pct`` (7.4). Divergence: the
    objective (frequency residue, or ||b|| without frequencies) above its best for ``patience``
    iterations in a row, or a model that can no longer be solved (e.g. a parameter driven
    negative); the best iterate is returned (also when ``max_iter`` runs out).
    solver_options: keyword arguments of the "ls"/"tls" solver (rank, rtol, jump, t_b, ...), or
    alpha0/factor of the Bayesian schedule. Each history entry holds p, the frequency residue,
    max frequency error, ||b||, pairs, MAC of the pairs, condition numbers per configuration and
    stacked, and the rank, message and step of the solve made from it; ``set_aside`` names the
    configurations none of whose modes paired at that iteration. ``progress(entry)`` is called with
    each history entry as it is made (long runs report per iteration).
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
        return np.where(is_log, np.log(v / q), v / q - 1)

    if solver == "bounded":
        if bounds is None:
            raise ValueError("solver 'bounded' needs bounds=(lower, upper) parameter values")
        lo, hi = (np.broadcast_to(np.asarray(v, float), p.shape) for v in bounds)
    line = (solver == "bayes") if use_line_search is None else use_line_search
    have_f = all(c.f_x is not None for c in configs)
    opts = dict(solver_options or {})

    history, best, best_obj, worse, last_sol = [], None, np.inf, 0, None
    converged, diverged, reason = False, False, "maximum number of iterations reached"
    for it in range(max_iter + 1):
        try:
            (A, b), blocks, states = build_equations(configs, p, pairing, stack_reduce)
        except (np.linalg.LinAlgError, ValueError, ArithmeticError) as exc:
            if it == 0:
                raise
            diverged, reason = True, f"diverged: the model could not be evaluated after step {it} ({exc})"
            break
        raw_norm = float(np.linalg.norm(np.concatenate([blk.b for blk in blocks])))
        paired = [st for st in states if not st.get("set_aside")]
        sigma = float(np.sqrt(np.mean([st["sigma"] ** 2 for st in paired]))) if have_f else None
        obj = sigma if have_f else raw_norm
        A = A[:, free]
        entry = {
            "iteration": it, "p": p.copy(), "sigma": sigma, "residual_norm": raw_norm,
            "max_freq_error_pct": max(st["max_err_pct"] for st in paired) if have_f else None,
            "pairs": [st.get("pairs") for st in states], "mac": [st.get("mac") for st in states],
            "set_aside": [c.name for c, st in zip(configs, states) if st.get("set_aside")],
            "condition_per_configuration": [condition_number(blk.A[:, free]) for blk in blocks],
            "condition_stacked": condition_number(A),
        }
        history.append(entry)
        if progress is not None:
            progress(entry)
        if obj < best_obj:
            best, best_obj, worse = it, obj, 0
        else:
            worse += 1
        if worse >= patience:
            diverged, reason = True, f"diverged: objective above its best (iteration {best}) for {patience} iterations"
            break
        if have_f and entry["max_freq_error_pct"] < tol_freq_pct:
            converged, reason = True, f"max frequency error {entry['max_freq_error_pct']:.3g} % < {tol_freq_pct} % (eq. 7.2)"
            break
        if it >= 1 and np.max(np.abs(history[-2]["proposed"])) * 100 < tol_param_pct:
            converged, reason = True, f"max parameter change < {tol_param_pct} % (eq. 7.3)"
            break
        if have_f and it >= 3:
            s = [h["sigma"] for h in history[-4:]]
            if np.mean(np.abs(np.diff(s))) * 100 < tol_sigma_pct:
                converged, reason = True, f"frequency residue changed < {tol_sigma_pct} % over three iterations (eq. 7.4)"
                break
        if it == max_iter:
            break
        if solver == "bayes":
            sol = SOLVERS[solver](A, b, alpha=bayes_alpha(it, opts.get("alpha0", 0.5), opts.get("factor", 0.9)))
        elif solver == "bounded":
            sol = SOLVERS[solver](A, b, rel_bound(lo, p)[free], rel_bound(hi, p)[free])
        else:
            sol = SOLVERS[solver](A, b, **opts)
        last_sol = sol
        entry.update(rank=sol.rank, rank_deficient=sol.rank_deficient, message=sol.message)
        x = np.zeros(p.size)
        x[free] = sol.x
        beta = 1.0
        if line and have_f:
            def residue(bt):
                trial = stepped(p, bt * x)
                try:
                    states = [_state(c, trial, pairing) for c in configs]
                    return float(np.sqrt(np.mean([st["sigma"] ** 2 for st in states if not st.get("set_aside")])))
                except (np.linalg.LinAlgError, ValueError, ArithmeticError):
                    return np.inf  # the trial model cannot be solved: not a candidate
            beta, _ = line_search(residue)
        entry.update(step=beta * x, proposed=x, beta=beta)
        if beta == 0.0:
            reason = f"stalled: the line search (eq. 7.6) found no decrease of the frequency residue at iteration {it}"
            break
        p = stepped(p, beta * x)
    final = len(history) - 1 if converged else best
    return UpdateResult(history[final]["p"], converged, diverged, reason, len(history) - 1, best, history, last_sol)
