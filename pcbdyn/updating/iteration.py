"""Updating configurations on plain callables and their equations (thesis section 4.9, 7.3.1, chapter 6).

A configuration is a model callable ``p -> (K, M, dKs, dMs)`` plus its measured data. At every
parameter state each configuration is re-solved, its modes re-paired (by MAC when shapes are measured,
through a ``pairing`` callable), its weighted equations built and all configurations stacked (PBC,
eq. 6.4); :mod:`.driver` iterates them. :func:`objective_rows` is what a fit minimises: the frequency
errors (and, for the "modal" method, the shape errors of :mod:`.shapes`) in units of their noise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..correlation.close_modes import align_close, close_groups
from ..correlation.mac import mac, paired_mac
from . import equations as eq
from . import matching
from .errors import UpdatingError
from .pbc import stack
from .sensitivity import frequencies_hz, pencil_modes
from .shapes import shape_derivatives, shape_residual, shape_rows, shape_sigma
from .solvers import frequency_residue
from .weighting import std_row_weights, unit_row_weights, weight_rows

METHODS = ("freq", "freq-rel", "modal", "fbm", "qms", "frf-in", "frf-out", "frf-direct")


@dataclass
class Configuration:
    """One test configuration (the main one or a perturbed one).

    model: p -> (K, M, dKs, dMs), the matrices and their parameter derivatives at p.
    f_x: measured natural frequencies [Hz] (frequency equations, pairing and convergence).
    phi_x: measured shapes (n_meas, n_modes) on the measured DOFs, one column per f_x.
    P: (n_meas, n_dof) maps model DOFs to measured DOFs (None: every DOF measured).
    frf_omegas, H_x, excitation: updating frequencies [rad/s], measured receptances
        (n_meas, n_freq) and the excited model DOF for the FRF methods.
    method: one of METHODS ("modal": frequencies and MAC-paired shapes in units of their noise,
        :mod:`.shapes`; needs ``sigma`` and ``shape_noise``). matching: "expand" (dynamic expansion of
        the data) or "reduce" (Guyan reduction of the model) when P is not None. damping: treatment of unknown damping
        in the data (appendix A): any of equations.DAMPING_TREATMENTS for "frf-in",
        "undamped"/"proportional" for "frf-out".
    sigma: standard deviations of the equations' rows (chi-squares weights, eq. 4.28; for the
        frequency methods one per measured frequency [Hz]); None gives unit-length rows (eq. 4.42).
    shape_noise: "modal": the standard deviation of a measured shape component as a fraction of its
        size (uniform bound / sqrt 3, eq. 5.73), one for all modes or one per measured mode.
    noise_f: the measurement's own standard deviation [Hz] of each measured frequency (the noise alone,
        not the model's share of ``sigma``): measured modes it cannot tell apart are compared as a plane
        (:mod:`pcbdyn.correlation.close_modes`: their MACs, and the "modal" shape rows); None: none are.
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
    shape_noise: float | None = None
    noise_f: np.ndarray | None = None

    @property
    def frf_hz(self) -> np.ndarray | None:
        return None if self.frf_omegas is None else np.asarray(self.frf_omegas, float) / (2 * np.pi)

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"method={self.method!r}; choose one of {METHODS}")
        if self.method.startswith("freq") and self.f_x is None:
            raise ValueError(f"configuration {self.name!r}: method {self.method!r} needs f_x (measured frequencies)")
        if self.method == "modal" and (self.phi_x is None or self.sigma is None or self.shape_noise is None):
            raise ValueError(f"configuration {self.name!r}: method 'modal' needs phi_x, sigma and shape_noise")
        if self.method in ("fbm", "qms") and (self.phi_x is None or self.f_x is None):
            raise ValueError(f"configuration {self.name!r}: method {self.method!r} needs f_x and phi_x")
        if self.method.startswith("frf") and (self.H_x is None or self.frf_omegas is None or self.excitation is None):
            raise ValueError(f"configuration {self.name!r}: method {self.method!r} needs frf_omegas, H_x and excitation")
        if self.matching not in ("expand", "reduce"):
            raise ValueError(f"matching={self.matching!r}; choose 'expand' or 'reduce'")


def mac_pairing(f_a, phi_a, f_x, phi_x) -> np.ndarray:
    """Analytical mode index for each measured mode: largest MAC, ties broken by the closest
    frequency, each analytical mode used once (greedy on decreasing MAC). Without shapes: by
    closest frequency. Pass pcbdyn.correlation's pairing instead when available."""
    f_a, f_x = np.asarray(f_a), np.asarray(f_x)
    if phi_x is None:
        score = -np.abs(f_a[:, None] / f_x[None, :] - 1)
    else:
        score = mac(phi_a, phi_x) - 1e-6 * np.abs(f_a[:, None] / f_x[None, :] - 1)
    pairs = -np.ones(f_x.size, int)
    S = score.copy()
    for _ in range(min(S.shape)):
        i, k = np.unravel_index(np.argmax(S), S.shape)
        pairs[k] = i
        S[i, :] = -np.inf
        S[:, k] = -np.inf
    return pairs


def _state(cfg: Configuration, p, pairing):
    """Model matrices, paired modes and residue of one configuration at p."""
    K, M, dKs, dMs = cfg.model(p)
    out = {"K": K, "M": M, "dKs": dKs, "dMs": dMs}
    if cfg.f_x is not None:
        n_modes = cfg.n_modes or min(K.shape[0], max(2 * np.size(cfg.f_x), np.size(cfg.f_x) + 4))
        out.update(paired_state(cfg, *pencil_modes(K, M, n_modes), pairing))
    return out


def paired_states(configs, p, pairing=None) -> list:
    """Each configuration's state at ``p`` (:func:`paired_state` of its solved modes; "set_aside" where
    nothing pairs), without its equations."""
    return [_state(c, np.asarray(p, float), pairing) for c in configs]


def paired_state(cfg: Configuration, lam, Phi, pairing=None) -> dict:
    """The measured modes of ``cfg`` paired among the computed eigenpairs (lam, Phi): "pairs" (analytical
    index per measured mode, -1 unpaired), "used" (the paired measured modes), their partners' "lam",
    "Phi", "f_a", "phi_am" (read at the measured DOFs), "mac", the frequency residue "sigma" and
    "max_err_pct"; all computed modes as "lam_all", "Phi_all" with the partners' "index"; with measured
    shapes, "x" (the paired measured shapes as compared, each group of close ones turned onto its
    partners') and "close" (those groups, as positions in "used"); "set_aside" when nothing pairs."""
    f_x = np.asarray(cfg.f_x, float)
    f_a = frequencies_hz(lam)
    phi_am = Phi if cfg.P is None else np.asarray(cfg.P @ Phi)
    pairs = np.asarray((cfg.pairing or pairing or mac_pairing)(f_a, phi_am, f_x, cfg.phi_x), int)
    used = np.flatnonzero(pairs >= 0)
    if used.size == 0:  # set aside at this state: nothing of it pairs
        return {"set_aside": True, "pairs": pairs, "used": used}
    ia = pairs[used]
    out = {"lam": lam[ia], "Phi": Phi[:, ia], "f_a": f_a[ia], "pairs": pairs, "used": used, "index": ia,
           "lam_all": lam, "Phi_all": Phi, "phi_am": phi_am[:, ia], "sigma": frequency_residue(f_a[ia], f_x[used]),
           "max_err_pct": float(np.max(np.abs(1 - f_a[ia] / f_x[used])) * 100)}
    if cfg.phi_x is not None:
        close = _close(cfg, used)
        x = align_close(np.asarray(cfg.phi_x)[:, used], phi_am[:, ia], close)
        out.update(x=x, close=close, mac=paired_mac(phi_am[:, ia], x))
    return out


def _close(cfg: Configuration, used) -> tuple:
    """The groups of close modes among the paired measured modes of ``cfg``, as positions in ``used``."""
    if cfg.noise_f is None:
        return ()
    return tuple(close_groups(np.asarray(cfg.f_x, float)[used], np.asarray(cfg.noise_f, float)[used]))


def _frequency_sigma(cfg, st) -> np.ndarray:
    """The standard deviation [Hz] of each paired measured frequency: ``cfg.sigma`` when it is one per
    measured frequency, else the frequency itself (relative errors)."""
    f_x = np.asarray(cfg.f_x, float)
    sig = np.asarray(cfg.sigma, float) if cfg.sigma is not None and np.size(cfg.sigma) == f_x.size else f_x
    return sig[st["used"]]


def objective_rows(cfg: Configuration, st) -> np.ndarray | None:
    """What a fit of ``cfg`` minimises the squares of at its state ``st``: the paired frequencies' errors
    f_x - f_a in units of their sigma (relative errors without one: the frequency residue of eq. 7.4)
    and, for "modal", every paired shape's residual in units of its noise (:mod:`.shapes`). None for a
    configuration without measured frequencies (the FRF methods: their ||b||)."""
    if cfg.f_x is None:
        return None
    if st.get("set_aside"):
        return np.zeros(0)
    used = st["used"]
    rows = [(np.asarray(cfg.f_x, float)[used] - st["f_a"]) / _frequency_sigma(cfg, st)]
    if cfg.method == "modal":
        for a, k in enumerate(used):
            d = np.asarray(st["x"][:, a], float)
            rows.append(shape_residual(d, st["phi_am"][:, a], shape_sigma(d, _shape_noise(cfg, k))))
    return np.concatenate(rows)


def _shape_noise(cfg: Configuration, k: int) -> float:
    return float(cfg.shape_noise if np.ndim(cfg.shape_noise) == 0 else cfg.shape_noise[k])


def unpaired(cfg: Configuration, st) -> int:
    """How many measured modes of ``cfg`` found no partner at the state ``st``."""
    return 0 if cfg.f_x is None else int(np.size(cfg.f_x) - np.size(st["used"]))


def _modal_block(cfg: Configuration, st, p) -> eq.Block:
    """The "modal" rows in units of their noise: the frequency equations (eqs. 3.2-3.3) over their sigma,
    then per paired mode its shape rows (:func:`.shapes.shape_rows`)."""
    K, M, dKs, dMs = st["K"], st["M"], st["dKs"], st["dMs"]
    used, sig = st["used"], _frequency_sigma(cfg, st)
    A_f, b_f = eq.frequency_equations(st["lam"], st["Phi"], np.asarray(cfg.f_x, float)[used], dKs, dMs, p)
    lam = st["lam_all"]
    shift = 0.0 if cfg.n_rigid == 0 else 0.1 * float(lam[min(cfg.n_rigid, lam.size - 1)])
    dphi = shape_derivatives(K, M, lam, st["Phi_all"], st["index"], dKs, dMs, shift, st["close"])
    A, b = [A_f / sig[:, None]], [b_f / sig]
    for a, k in enumerate(used):
        d = np.asarray(st["x"][:, a], float)
        du = dphi[:, :, a].T if cfg.P is None else np.asarray(cfg.P @ dphi[:, :, a].T)
        A_s, b_s = shape_rows(d, st["phi_am"][:, a], du, shape_sigma(d, _shape_noise(cfg, k)), p)
        A.append(A_s)
        b.append(b_s)
    return eq.Block(np.vstack(A), np.concatenate(b))


def _block(cfg: Configuration, st, p) -> eq.Block:
    K, M, dKs, dMs = st["K"], st["M"], st["dKs"], st["dMs"]
    used = st.get("used")
    if cfg.method == "modal":
        return _modal_block(cfg, st, p)
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
    if (cfg.sigma is None and cfg.method == "frf-in" and _condensed(cfg)) or cfg.method == "modal":
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
    states = paired_states(configs, p, pairing)
    active = [(c, st) for c, st in zip(configs, states) if not st.get("set_aside")]
    if not active:
        raise UpdatingError("no measured mode of any configuration found an analytical partner; check that test and "
                         "model are the same structure and configuration, and the points' frame and units")
    blocks = [_block(c, st, p) for c, st in active]
    stacked = stack([_weighted(c, blk, st) for (c, st), blk in zip(active, blocks)], reduce=stack_reduce)
    return stacked, blocks, states
