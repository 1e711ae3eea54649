"""Steinberg's fatigue check of the lead wires and solder joints of parts on a vibrating board
(the design method the 1999 thesis names in its chapter 1, reference [63]).

Sources: D. S. Steinberg, *Vibration Analysis for Electronic Equipment*, 3rd ed., Wiley 2000
(the allowable board displacement, the three-band technique, Q = sqrt(f_n), the octave rule) and
T. Irvine, *Extending Steinberg's Fatigue Analysis of Electronics Equipment Methodology to a Full
Relative Displacement vs. Cycles Curve*, rev. C, 2013 (one displacement S-N curve through
Steinberg's limit, for random and sine cycles alike).

- Allowable displacement (inches): Z = 0.00022 B / (c h r sqrt(L)), B the board edge length
  parallel to the part, L the part's length, h the board thickness, c the package constant and r
  the relative position factor (1 at the board's centre, 0.707 at the half/quarter point, 0.5 at
  the quarter/quarter point). A Gaussian random response whose 3-sigma displacement at the
  board's centre equals Z gives about 2e7 stress reversals before failure. Steinberg's shock
  limit is six times Z (his eq. 11.23, 0.00132 B / (c h r sqrt(L))).
- S-N curve: N(z) = N_ref (Z / z)^b with b = 6.4 (lead wires and solder joints). N_ref is set so
  that the three-band technique (Steinberg: the response spends 68.3 %, 27.1 % and 4.33 % of its
  cycles at 1, 2 and 3 sigma) with 3 sigma = Z gives 2e7 cycles, which makes it Steinberg's own
  life formula N = 2e7 (Z / z_3sigma)^b (N_ref = 1.28e6 cycles at z = Z; Irvine's curve,
  calibrated by rainflow counting instead, has 1.12e6).
- Damage: Miner's rule, D = sum n_i / N_i; a random response makes its cycles at its zero
  up-crossing rate nu_0 = sqrt(m2 / m0) (Rice; f_n for one mode, as Steinberg counts them).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import trapezoid

INCH = 0.0254
#: Steinberg's coefficient of the allowable displacement, for lengths in inches
STEINBERG_COEFF = 0.00022
#: stress reversals a 3-sigma displacement equal to the allowable gives (random vibration)
N_ALLOWABLE = 2.0e7
#: fatigue exponent of lead wires and solder joints (Steinberg)
B_EXPONENT = 6.4
#: Steinberg's shock allowable over his vibration one (his eq. 11.23: 0.00132 B / (c h r sqrt(L)))
SHOCK_FACTOR = 6.0
#: Steinberg's three bands: (multiple of sigma, fraction of the cycles)
BANDS = ((1.0, 0.683), (2.0, 0.271), (3.0, 0.0433))


def allowable_displacement(span: float, length: float, thickness: float, c: float, r: float = 1.0) -> float:
    """Steinberg's allowable single-amplitude board displacement [m] for 2e7 reversals at 3 sigma.

    ``span`` B, ``length`` L and ``thickness`` h in metres (the formula is in inches), ``c`` the
    package constant, ``r`` the relative position factor (> 0)."""
    if min(span, length, thickness, c, r) <= 0:
        raise ValueError("span, length, thickness, c and r must all be positive")
    z_in = STEINBERG_COEFF * (span / INCH) / (c * (thickness / INCH) * r * np.sqrt(length / INCH))
    return float(z_in * INCH)


def shock_allowable_displacement(span: float, length: float, thickness: float, c: float, r: float = 1.0) -> float:
    """Steinberg's allowable peak board displacement [m] under shock: ``SHOCK_FACTOR`` times the
    vibration allowable of :func:`allowable_displacement` (same arguments)."""
    return SHOCK_FACTOR * allowable_displacement(span, length, thickness, c, r)


def reference_cycles(b: float = B_EXPONENT) -> float:
    """N_ref: cycles to failure at a displacement amplitude equal to the allowable (see module)."""
    return N_ALLOWABLE * sum(p * (k / 3.0) ** b for k, p in BANDS)


def cycles_to_failure(z, z_allow: float, b: float = B_EXPONENT) -> np.ndarray:
    """N(z) = N_ref (z_allow / z)^b; infinite where z = 0."""
    z = np.asarray(z, dtype=float)
    with np.errstate(divide="ignore"):
        return reference_cycles(b) * (z_allow / z) ** b


def random_life(z_rms: float, z_allow: float, rate: float, b: float = B_EXPONENT) -> float:
    """Time to failure [s] under a stationary Gaussian response of RMS ``z_rms`` making ``rate``
    cycles per second: three-band technique and Miner's rule (inf when nothing moves)."""
    if z_rms <= 0 or rate <= 0:
        return float("inf")
    damage_per_cycle = sum(p / cycles_to_failure(k * z_rms, z_allow, b) for k, p in BANDS)
    return float(1.0 / (rate * damage_per_cycle))


def sweep_damage(freqs, z_amp, z_allow: float, rate_oct_min: float, b: float = B_EXPONENT) -> float:
    """Miner damage of one logarithmic sine sweep through ``freqs`` [Hz] (sorted, a fine grid),
    the displacement amplitude being ``z_amp`` [m] at each frequency.

    At r octaves per minute a sweep spends dt = 60 d(ln f) / (r ln 2) seconds about f and makes
    f dt cycles there; D = integral of those cycles over N(z(f)) (trapezoid rule in ln f)."""
    f = np.asarray(freqs, dtype=float)
    cycles_per_lnf = 60.0 * f / (rate_oct_min * np.log(2.0))
    return float(trapezoid(cycles_per_lnf / cycles_to_failure(z_amp, z_allow, b), np.log(f)))


def zero_crossing_rate(m0: float, m2: float) -> float:
    """Rice's rate of zero up-crossings nu_0 = sqrt(m2 / m0) [Hz] from the spectral moments
    m_k = integral of f^k G(f) df of a response PSD G."""
    return float(np.sqrt(m2 / m0)) if m0 > 0 else 0.0


def octave_rule(f_board: float, f_chassis: float) -> dict:
    """Steinberg's octave rule: a board's fundamental should lie at least an octave above the
    chassis resonance (or, the reverse rule, an octave below it) so that the two do not couple.

    Returns the ratio, which rule holds (if any) and a one-line verdict."""
    ratio = f_board / f_chassis
    if ratio >= 2.0:
        rule, ok = "forward: f_board >= 2 f_chassis", True
    elif ratio <= 0.5:
        rule, ok = "reverse: f_board <= f_chassis / 2", True
    else:
        rule, ok = "within an octave of the chassis: the two resonances couple", False
    return {"board_hz": float(f_board), "chassis_hz": float(f_chassis), "ratio": float(ratio), "ok": ok, "rule": rule}
