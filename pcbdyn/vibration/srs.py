"""Shock response spectra: the standard SRS of an acceleration record (maximax absolute acceleration
of base-excited oscillators, Q = 10 unless stated, at 1/12-octave points), its pseudo-velocity, and
the rules that combine peak modal responses when the input is an SRS.

The record is taken as piecewise linear between its samples and zero after its last one; each
oscillator is integrated exactly (:mod:`.transient`) on sub-steps of at most 1/``POINTS_PER_CYCLE``
of its period, so that the sampled peak lies within 1 - cos(pi / 64) = 0.12 % of the true one
while the input lasts; after it, the peak of the free decay is found exactly (:func:`.transient.free_peak`).
Pseudo-velocity PV = SRS / (2 pi f): the severity screen draws 100 in/s (2.54 m/s), above which
shocks are known to damage equipment (H. A. Gaberson, "Shock severity estimation", Sound and
Vibration, January 2012).
"""

from __future__ import annotations

import numpy as np

from .spectra import VibrationError
from .transient import Oscillators, Peaks, free_peak, refine, states

#: samples of the response per period of an oscillator while the input lasts
POINTS_PER_CYCLE = 64
#: the pseudo-velocity of the severity line, 100 in/s [m/s]
PV_SEVERE = 2.54
#: combinations of peak modal responses for an SRS input
COMBINATIONS = ("srss", "abs", "nrl")


def octave_points(f_lo: float, f_hi: float, per_octave: int = 12) -> np.ndarray:
    """f_lo 2^(k / per_octave) for k = 0 .. the nearest point to f_hi [Hz] (10 Hz-10 kHz at
    1/12 octave: 121 points, the last 10.24 kHz)."""
    if not 0 < f_lo < f_hi:
        raise VibrationError(f"the SRS band {f_lo:g}-{f_hi:g} Hz must have 0 < lower < upper")
    n = int(round(per_octave * np.log2(f_hi / f_lo)))
    return f_lo * 2.0 ** (np.arange(n + 1) / per_octave)


def srs(t, a, freqs, q: float = 10.0) -> np.ndarray:
    """Maximax absolute acceleration (the unit of ``a``) of oscillators at ``freqs`` [Hz] with
    quality factor ``q`` under the base acceleration ``a`` at times ``t`` [s] (piecewise linear,
    zero after the last sample; the absolute acceleration of an oscillator depends on its state
alone, so a record that ends away from zero needs no ramp down)."""
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    freqs = np.asarray(freqs, dtype=float)
    out = np.zeros(freqs.size)
    longest = float(np.diff(t).max()) if t.size > 1 else 0.0
    subs = np.maximum(1, np.ceil(longest * POINTS_PER_CYCLE * freqs - 1e-9)).astype(int)
    for n in np.unique(subs):  # oscillators that need the same sub-steps share one grid
        pick = np.flatnonzero(subs == n)
        osc = Oscillators(freqs[pick], np.full(pick.size, 0.5 / q))
        tt, aa, h = refine(t, a, longest / n if longest > 0 else 1.0)
        c = osc.acceleration_weight()
        peaks = Peaks(pick.size)
        y = None
        for k0, y in states(osc, aa, h):
            peaks.update(tt[k0:k0 + y.shape[0]], (y * c).real)
        if y is not None:
            residual, _ = free_peak(osc, c * y[-1])  # the input is zero from here on
            out[pick] = np.maximum(peaks.magnitude, residual)
    return out


def pseudo_velocity(freqs, srs_values) -> np.ndarray:
    """PV = SRS / (2 pi f) [m/s for an SRS in m/s^2]."""
    return np.asarray(srs_values, dtype=float) / (2.0 * np.pi * np.asarray(freqs, dtype=float))


def combine(terms: np.ndarray, rule: str) -> np.ndarray:
    """Combine peak responses ``terms`` (n_outputs, n_terms) per output row: "srss" (square root
    of the sum of squares), "abs" (sum of magnitudes, an upper bound) or "nrl" (the largest plus
    the SRSS of the others; the U.S. Naval Research Laboratory's rule for shipboard shock)."""
    m = np.abs(np.asarray(terms, dtype=float))
    if rule == "srss":
        return np.sqrt((m**2).sum(axis=1))
    if rule == "abs":
        return m.sum(axis=1)
    if rule == "nrl":
        top = m.max(axis=1)
        return top + np.sqrt(np.maximum((m**2).sum(axis=1) - top**2, 0.0))
    raise VibrationError(f"--combine '{rule}': use one of {', '.join(COMBINATIONS)}")
