"""Exact response of damped oscillators to a piecewise-linear input: the ramp-invariant recursion.

An oscillator z'' + 2 zeta w z' + w^2 z = f(t) (a mode in modal coordinates, thesis eq. 3.27 with
modal damping, or one oscillator of a shock response spectrum) has the poles s, conj(s) =
-zeta w +- i w_d. With y = z' - conj(s) z it becomes the complex first-order y' = s y + f, and
z = Im(y) / w_d, z' = Re(y) - zeta w z. Over a step of length h on which f is linear from f0 to f1,

    y1 = e^{sh} y0 + h (phi1(sh) - phi2(sh)) f0 + h phi2(sh) f1,
    phi1(x) = (e^x - 1) / x,  phi2(x) = (e^x - 1 - x) / x^2,

exactly (the ramp-invariant discretisation; D. O. Smallwood, "An improved recursive formula for
calculating shock response spectra", Shock and Vibration Bulletin 51, 1981, derives the same
filter for the shock response spectrum). So a piecewise-linear input is integrated with no
time-step error at all: a step may be cut into any number of sub-steps (to sample the response
finely enough to see its peaks) without changing the answer at the input's breakpoints. A step of
zero length (a jump of the input, as at the end of a terminal-peak sawtooth) leaves y unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import lfilter

from .spectra import VibrationError

#: output points per block of the recursion (bounds the memory of long records)
BLOCK = 4096
#: most time points a response is sampled at (three arrays of this length are held)
MAX_STEPS = 5_000_000
#: steps whose lengths differ by less than this fraction of the longest step are taken as equal
_SAME_STEP = 1e-9
_TAYLOR = 18  # terms of the phi series used for |x| < 0.5 (the next term is below 1e-21)


def _phi12(x: np.ndarray) -> tuple:
    """phi1(x), phi2(x) of complex ``x`` (a Taylor series near 0, where the closed forms cancel)."""
    x = np.asarray(x, dtype=complex)
    phi1, phi2 = np.empty_like(x), np.empty_like(x)
    small = np.abs(x) < 0.5
    xs, xl = x[small], x[~small]
    term1, term2 = np.ones_like(xs), np.full_like(xs, 0.5)
    s1, s2 = term1.copy(), term2.copy()
    for k in range(1, _TAYLOR):
        term1 = term1 * xs / (k + 1)
        term2 = term2 * xs / (k + 2)
        s1, s2 = s1 + term1, s2 + term2
    phi1[small], phi2[small] = s1, s2
    e = np.exp(xl)
    phi1[~small], phi2[~small] = (e - 1.0) / xl, (e - 1.0 - xl) / xl**2
    return phi1, phi2


@dataclass(frozen=True)
class Oscillators:
    """Damped oscillators of natural frequencies ``f`` [Hz] and damping ratios ``zeta`` (0 < zeta < 1)."""

    f: np.ndarray
    zeta: np.ndarray

    @property
    def w(self) -> np.ndarray:
        return 2.0 * np.pi * np.asarray(self.f, dtype=float)

    @property
    def s(self) -> np.ndarray:
        """The pole -zeta w + i w_d of each oscillator."""
        z = np.asarray(self.zeta, dtype=float)
        return self.w * (-z + 1j * np.sqrt(1.0 - z**2))

    def step(self, h: float) -> tuple:
        """(e^{sh}, coefficient of f0, coefficient of f1) of one step of length ``h``."""
        x = self.s * h
        phi1, phi2 = _phi12(x)
        return np.exp(x), h * (phi1 - phi2), h * phi2

    def displacement(self, y: np.ndarray) -> tuple:
        """(z, z') from the complex states ``y`` (..., n_oscillators)."""
        z = y.imag / self.s.imag
        return z, y.real - np.asarray(self.zeta) * self.w * z

    def acceleration_weight(self) -> np.ndarray:
        """c with -2 zeta w z' - w^2 z = Re(c y): the absolute acceleration of a base-excited
        oscillator (z relative to the base), or z'' of a free one."""
        s, zw = self.s, np.asarray(self.zeta) * self.w
        return -2.0 * zw * (1.0 + 1j * zw / s.imag) + 1j * self.w**2 / s.imag


def refine(t: np.ndarray, a: np.ndarray, h_max: float) -> tuple:
    """(times, values, step lengths) of the piecewise-linear input (``t``, ``a``) with every step cut
    into equal sub-steps no longer than ``h_max`` (a zero-length step, a jump, is kept as it is)."""
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    length = np.diff(t)
    n = np.maximum(1, np.ceil(length / h_max - 1e-9))
    if n.sum() > MAX_STEPS:
        raise VibrationError(f"the input spans {t[-1] - t[0]:.4g} s: sampling the response {1 / h_max:.4g} times per "
                             f"second takes {n.sum():.3g} points, more than {MAX_STEPS:.0e}; shorten the record to the "
                             "shock itself (or lower the highest frequency asked for)")
    n = n.astype(int)
    seg = np.repeat(np.arange(length.size), n)
    frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    tt = np.append(t[seg] + frac * length[seg], t[-1])
    aa = np.append(a[seg] + frac * (a[seg + 1] - a[seg]), a[-1])
    return tt, aa, np.repeat(length / n, n)


def _chunks(h: np.ndarray, block: int):
    """(first step, end step, step length) of runs of steps of one length, cut at every ``block`` steps."""
    if h.size == 0:
        return
    key = np.round(h / (h.max() or 1.0) / _SAME_STEP).astype(np.int64)
    starts = np.concatenate([[0], np.flatnonzero(np.diff(key)) + 1])
    ends = np.append(starts[1:], h.size)
    for k0, k1 in zip(starts, ends):
        for c0 in range(int(k0), int(k1), block):
            yield c0, min(c0 + block, int(k1)), float(h[c0])


def states(osc: Oscillators, a: np.ndarray, h: np.ndarray, block: int = BLOCK):
    """The complex states of the oscillators (at rest at the first point) under the input ``a`` given
    at the points of a grid with step lengths ``h``, block by block: yields (first point index,
    states (n_points_in_block, n_oscillators)); the first block starts with point 0."""
    y = np.zeros(np.size(osc.f), dtype=complex)
    yield 0, y[None, :].copy()
    for k0, k1, hk in _chunks(h, block):
        lam, b0, b1 = osc.step(hk)
        u = a[k0:k1, None] * b0 + a[k0 + 1:k1 + 1, None] * b1
        out = np.empty(u.shape, dtype=complex)
        for j in range(lam.size):
            out[:, j] = lfilter([1.0], [1.0, -lam[j]], u[:, j], zi=[lam[j] * y[j]])[0]
        y = out[-1].copy()
        yield k0 + 1, out


class Peaks:
    """The largest magnitude of each of ``n`` outputs over time, with its signed value and time."""

    def __init__(self, n: int):
        self.magnitude = np.zeros(n)
        self.value = np.zeros(n)
        self.time = np.zeros(n)

    def update(self, t: np.ndarray, values: np.ndarray) -> None:
        """Fold in ``values`` (n_times, n) at times ``t``."""
        k = np.argmax(np.abs(values), axis=0)
        cols = np.arange(values.shape[1])
        v = values[k, cols]
        better = np.abs(v) > self.magnitude
        self.magnitude[better], self.value[better], self.time[better] = np.abs(v[better]), v[better], t[k[better]]


def free_peak(osc: Oscillators, w: np.ndarray) -> tuple:
    """(max over tau >= 0 of |Re(w e^{s tau})|, the tau of it): the peak of an output of freely
    decaying oscillators, exactly. Re(w e^{s tau}) = |w| e^{-zeta w_n tau} cos(w_d tau + arg w) has
    its extrema where w_d tau + arg w = k pi - asin(zeta); the first at tau >= 0 is the largest one
    after tau = 0 (each later one is smaller by the decay), so the peak is it or the start."""
    s = osc.s
    wd, theta = s.imag, np.angle(w)
    k = np.ceil((theta + np.arcsin(osc.zeta)) / np.pi)
    tau = (k * np.pi - np.arcsin(osc.zeta) - theta) / wd
    at_tau = np.abs((w * np.exp(s * tau)).real)
    at_zero = np.abs(w.real)
    later = at_tau > at_zero
    return np.where(later, at_tau, at_zero), np.where(later, tau, 0.0)
