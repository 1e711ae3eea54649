"""Closed-form response of a damped oscillator to a half-sine base acceleration (no recursion, no
time stepping of pcbdyn's): the forced solution while the pulse lasts, the free decay after it."""

import numpy as np
from scipy.optimize import minimize_scalar


def half_sine_response(f: float, zeta: float, peak: float, duration: float):
    """A function of time t [s] -> (z, z') of z'' + 2 zeta w z' + w^2 z = -peak sin(pi t / T) for
    t <= T (0 after), starting at rest: the relative displacement of an oscillator on the base."""
    w, big = 2 * np.pi * f, np.pi / duration
    wd, zw = w * np.sqrt(1 - zeta**2), zeta * w
    X = -peak / (w**2 - big**2 + 2j * zeta * w * big)  # particular: Im(X e^{i big t})

    def forced(t):
        zp, vp = (X * np.exp(1j * big * t)).imag, (1j * big * X * np.exp(1j * big * t)).imag
        c1 = -X.imag
        c2 = (zw * c1 - (1j * big * X).imag) / wd
        e = np.exp(-zw * t)
        z = zp + e * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
        v = vp + e * (-zw * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t)) + wd * (-c1 * np.sin(wd * t) + c2 * np.cos(wd * t)))
        return z, v

    zT, vT = forced(duration)
    d1, d2 = zT, (vT + zw * zT) / wd

    def response(t):
        t = np.asarray(t, dtype=float)
        tau = np.maximum(t - duration, 0.0)
        e = np.exp(-zw * tau)
        zf = e * (d1 * np.cos(wd * tau) + d2 * np.sin(wd * tau))
        vf = e * (-zw * (d1 * np.cos(wd * tau) + d2 * np.sin(wd * tau)) + wd * (-d1 * np.sin(wd * tau) + d2 * np.cos(wd * tau)))
        zi, vi = forced(np.minimum(t, duration))
        inside = t <= duration
        return np.where(inside, zi, zf), np.where(inside, vi, vf)

    return response


def maximax(fun, t_end: float, n: int = 20000) -> tuple:
    """(max |fun(t)| over 0 <= t <= t_end, its t): a dense grid, then a bounded search around its best."""
    t = np.linspace(0.0, t_end, n)
    k = int(np.argmax(np.abs(fun(t))))
    lo, hi = t[max(k - 1, 0)], t[min(k + 1, n - 1)]
    r = minimize_scalar(lambda x: -abs(float(fun(x))), bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-12 * max(t_end, 1e-9)})
    return max(abs(float(fun(r.x))), float(np.abs(fun(t)).max())), float(r.x)


def half_sine_srs(f: float, q: float, peak: float, duration: float) -> float:
    """Maximax absolute acceleration -2 zeta w z' - w^2 z of the oscillator at ``f`` [Hz]."""
    zeta, w = 0.5 / q, 2 * np.pi * f
    resp = half_sine_response(f, zeta, peak, duration)

    def acc(t):
        z, v = resp(t)
        return -2 * zeta * w * v - w**2 * z

    return maximax(acc, duration + 1.5 / f)[0]
