"""Which lines of measured FRFs to update on (thesis section 2.2.3), and the model's receptances there."""

from __future__ import annotations

import numpy as np

from ..correlation.frf import fdac
from ..fe.modal import eigenpairs
from .errors import UpdatingError


def resonance_lines(f, H) -> np.ndarray:
    """Frequencies [Hz] of the local maxima of sum_i |H_i|^2 over the lines (the resonances seen on the
    sampled FRFs, H (n_f, n_resp))."""
    s = np.sum(np.abs(H) ** 2, axis=1)
    k = np.flatnonzero((s[1:-1] > s[:-2]) & (s[1:-1] > s[2:])) + 1
    return np.asarray(f)[k]


def choose_frf_frequencies(f, H_x, H_a, gap: float = 0.1, n_max: int = 8, min_fdac: float = 0.9,
                           free: bool = False):
    """Automatic updating frequencies (thesis section 2.2.3): indices of lines of ``f`` [Hz].

    Rule: resonances are the peaks of the measured (``H_x``) and model (``H_a``) FRFs (both (n_f,
    n_resp)); a line qualifies when it lies more than ``gap`` (relative) from every resonance (the
    receptance there is not dominated by one mode and a frequency shift between model and test does
    not flip it) and its FDAC between test and model at that same line (eq. 2.6, diagonal) is at least
    ``min_fdac``. In each interval between consecutive resonances (and below the first, above the
    last) the qualifying line with the highest FDAC is taken; of these, the ``n_max`` with the highest
    FDAC are kept. A ``free`` structure has no lines below its first resonance: there the response
    is the rigid-body mass line, which no stiffness parameter moves. Returns (indices sorted by
    frequency, FDAC of every line, note or None); when no line reaches ``min_fdac`` the
    best-correlated lines are taken and the note says so.
    """
    f = np.asarray(f, float)
    res = np.unique(np.concatenate([resonance_lines(f, H_x), resonance_lines(f, H_a)]))
    cos = np.diagonal(fdac(H_x, H_a)[0]).copy()
    away = (f > (res[0] if free and res.size else 0.0)) & np.all(
        np.abs(f[:, None] / np.where(res > 0, res, np.inf)[None, :] - 1) > gap, axis=1)
    interval = np.searchsorted(res, f)
    note = None
    ok = away & (cos >= min_fdac)
    if not ok.any():
        ok = away
        note = (f"no line away from the resonances has FDAC >= {min_fdac}; the best-correlated ones are used "
                "(check the pairing of test and model, or give --frf-freqs)")
    if not ok.any():
        raise UpdatingError("no measured line lies away from the resonances; give the updating frequencies (--frf-freqs)")
    picks = [k[np.argmax(cos[k])] for i in np.unique(interval[ok]) for k in [np.flatnonzero(ok & (interval == i))]]
    picks = sorted(picks, key=lambda k: -cos[k])[:n_max]
    return np.sort(np.asarray(picks, int)), cos, note


def model_receptance(K, M, P, j: int, omegas) -> np.ndarray:
    """Undamped model receptances (n_w, n_meas) P H(w) e_j at ``omegas`` [rad/s] by modal
    superposition (eq. 3.29 with no damping) of every mode up to three times the highest frequency,
    rigid-body modes included: accurate enough to find resonances and correlated lines, and one
    eigensolution instead of a factorisation per line."""
    w = np.asarray(omegas, float)
    lam, Phi, _ = eigenpairs(K, M, f_max=3 * w.max() / (2 * np.pi), free=True)
    with np.errstate(divide="ignore"):
        terms = (P @ Phi) * Phi[j]
        return np.real_if_close(terms @ (1.0 / (lam[:, None] - w[None, :] ** 2))).T
