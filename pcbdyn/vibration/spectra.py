"""Vibration specifications: acceleration PSDs (random) and sine sweeps, read from CSV files with
units in the header or taken by name from the bundled standard levels, and the frequency grid on
which response spectra are integrated.

A PSD is given by breakpoints and is a straight line between them on log-log axes (constant dB per
octave), as specifications are written; its mean square is integrated exactly segment by segment
(for W = W1 (f/f1)^n: W1 f1 ((f2/f1)^(n+1) - 1) / (n + 1), or W1 f1 ln(f2/f1) when n = -1).
Values are SI inside: frequencies in Hz, PSDs in (m/s^2)^2/Hz, accelerations in m/s^2.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..units import UnitError, shown, to_si

#: standard gravity [m/s^2]: the "g" of vibration specifications
G = 9.80665
_GEVS = ("NASA GSFC-STD-7000 (GEVS), component random vibration: the generalized test levels for components "
         "of 22.7 kg or less")
#: bundled input PSDs: name -> (breakpoints [(Hz, g^2/Hz)], source, duration per axis [s], overall grms stated)
NAMED_PSDS = {
    "gevs-qual": ([(20, 0.026), (50, 0.16), (800, 0.16), (2000, 0.026)],
                  f"{_GEVS}, qualification (14.1 grms, 2 min per axis)", 120.0, 14.1),
    "gevs-accept": ([(20, 0.013), (50, 0.08), (800, 0.08), (2000, 0.013)],
                    f"{_GEVS}, acceptance (10.0 grms, 1 min per axis)", 60.0, 10.0),
    "gevs-workmanship": ([(20, 0.01), (80, 0.04), (500, 0.04), (2000, 0.01)],
                         "NASA GSFC-STD-7000 (GEVS), component random vibration: the minimum workmanship level "
                         "(6.8 grms, 1 min per axis)", 60.0, 6.8),
}
_COLUMN = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_ ]*?)\s*(?:\[\s*([^\]]*?)\s*\])?\s*$")


def loglog(x, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """Straight lines between the breakpoints (xp, fp) on log-log axes, 0 outside [xp[0], xp[-1]]."""
    x = np.asarray(x, dtype=float)
    inside = (x >= xp[0]) & (x <= xp[-1])
    out = np.zeros_like(x)
    out[inside] = np.exp(np.interp(np.log(x[inside]), np.log(xp), np.log(fp)))
    return out


@dataclass(frozen=True)
class _Column:
    si: np.ndarray
    raw: np.ndarray  # as written, in ``unit``
    unit: str
    kind: int  # which of the accepted kinds of unit matched


class VibrationError(ValueError):
    """A vibration input that cannot be used; the message names the file or option, the field and the fix."""


@dataclass(frozen=True)
class Psd:
    """An acceleration PSD by breakpoints ``f`` [Hz], ``w`` [(m/s^2)^2/Hz], log-log in between.

    ``duration`` [s]: the test time per axis the specification states (None if it states none)."""

    name: str
    source: str
    f: np.ndarray
    w: np.ndarray
    duration: float | None = None

    @property
    def slopes(self) -> np.ndarray:
        """Exponent n of each segment, W ~ f^n (n = dB/octave / 3.01)."""
        return np.log(self.w[1:] / self.w[:-1]) / np.log(self.f[1:] / self.f[:-1])

    def at(self, freqs) -> np.ndarray:
        """W(f) [(m/s^2)^2/Hz], log-log between breakpoints, 0 outside the specified band."""
        return loglog(freqs, self.f, self.w)

    def mean_square(self) -> float:
        """Integral of W over the band [(m/s^2)^2], exact for power-law segments."""
        f1, w1, n = self.f[:-1], self.w[:-1], self.slopes
        ratio = self.f[1:] / f1
        flat = np.abs(n + 1.0) < 1e-9
        seg = np.where(flat, w1 * f1 * np.log(ratio),
                       w1 * f1 * (ratio ** np.where(flat, 0.0, n + 1.0) - 1.0) / np.where(flat, 1.0, n + 1.0))
        return float(seg.sum())

    def grms(self) -> float:
        """Overall RMS acceleration [m/s^2]."""
        return float(np.sqrt(self.mean_square()))


@dataclass(frozen=True)
class SineSweep:
    """A logarithmic sine sweep: breakpoints ``f`` [Hz] of the peak ``amplitude`` (an acceleration
    [m/s^2], or a displacement [m] when ``kind`` is "displacement"), log-log in between, swept at
    ``rate`` octaves per minute, ``sweeps`` times through the band."""

    name: str
    f: np.ndarray
    amplitude: np.ndarray
    kind: str
    rate: float
    sweeps: int = 1

    def acceleration(self, freqs) -> np.ndarray:
        """Peak base acceleration [m/s^2] at ``freqs`` (0 outside the band)."""
        f = np.asarray(freqs, dtype=float)
        a = loglog(f, self.f, self.amplitude)
        return a * (2.0 * np.pi * f) ** 2 if self.kind == "displacement" else a


def _check_breakpoints(where: str, f: np.ndarray, v: np.ndarray, what: str, units=("Hz", "")) -> None:
    """Clear errors for too few rows, frequencies not increasing, values not > 0; ``f`` and ``v``
    as written (in ``units``), so the message quotes the file."""
    fu, vu = units
    if f.size < 2:
        raise VibrationError(f"{where}: a {what} needs at least two breakpoints (frequency, value)")
    bad = np.flatnonzero(f <= 0)
    if bad.size:
        raise VibrationError(f"{where}: data row {bad[0] + 1}: frequency {f[bad[0]]:g} {fu} must be above 0")
    down = np.flatnonzero(np.diff(f) <= 0)
    if down.size:
        i = down[0] + 1
        raise VibrationError(f"{where}: data row {i + 1}: frequency {f[i]:g} {fu} does not rise above the row before "
                             f"({f[i - 1]:g} {fu}); sort the rows by increasing frequency, each frequency once")
    neg = np.flatnonzero(v <= 0)
    if neg.size:
        i = neg[0]
        raise VibrationError(f"{where}: data row {i + 1}: {what} value {v[i]:g} {vu} at {f[i]:g} {fu} must be above 0 "
                             "(a spectrum is log-log between breakpoints; start it where it is not zero)")


def _read_columns(path: Path, spec: dict) -> dict:
    """{name: Column} of a CSV whose header gives each column as 'name [unit]'; ``spec``: {name:
    [(pint unit, unit as shown in messages), ...]}, the kinds of unit accepted, tried in turn."""
    import pandas as pd

    from ..inputs import read_csv

    df = read_csv(path, VibrationError, skipinitialspace=True)
    cols = {}
    for c in df.columns:
        m = _COLUMN.match(str(c)[:100])
        if m:
            cols[m.group(1).strip().lower()] = (str(c), m.group(2))
    out = {}
    for name, units in spec.items():
        example = f"{name} [{units[0][1]}]"
        if name not in cols:
            raise VibrationError(f"{path}: no column '{name}'; the header must name it with its unit, e.g. '{example}'")
        col, unit = cols[name]
        if not unit:
            raise VibrationError(f"{path}: column '{col}' has no unit; write it as '{example}'")
        raw = pd.to_numeric(df[col], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(raw))
        if bad.size:
            raise VibrationError(f"{path}: data row {bad[0] + 1}: column '{col}' holds {shown(df[col].iloc[bad[0]])}, "
                                 "not a number")
        for k, (expected, _) in enumerate(units):
            try:
                scale = to_si(f"1 {unit}", expected, f"{path}: column '{col}'")
            except UnitError as exc:
                if k == len(units) - 1:
                    raise VibrationError(f"{exc}; e.g. '{example}'") from None
                continue
            out[name] = _Column(raw * scale, raw, unit, k)
            break
    return out


def read_psd_csv(path) -> Psd:
    """A PSD from a CSV with columns 'frequency [Hz]' and 'psd [g^2/Hz]' (any units of those kinds)."""
    path = Path(path)
    f, w = _read_columns(path, {"frequency": [("Hz", "Hz")], "psd": [("g_n^2/Hz", "g^2/Hz")]}).values()
    _check_breakpoints(str(path), f.raw, w.raw, "PSD", (f.unit, w.unit))
    return Psd(path.stem, str(path), f.si, w.si)


def named_psd(name: str) -> Psd:
    """A bundled standard PSD (see :data:`NAMED_PSDS`)."""
    if name not in NAMED_PSDS:
        raise VibrationError(f"--psd '{name}' is neither a CSV file nor a bundled spectrum; bundled: "
                             f"{', '.join(NAMED_PSDS)} (or give a CSV with columns 'frequency [Hz]', 'psd [g^2/Hz]')")
    points, source, duration, _ = NAMED_PSDS[name]
    f, w = np.array(points, dtype=float).T
    return Psd(name, source, f, w * G**2, duration)


def load_psd(text: str) -> Psd:
    """``--psd``: an existing CSV file, or the name of a bundled spectrum."""
    path = Path(text)
    return read_psd_csv(path) if path.is_file() else named_psd(text)


def read_sine_csv(path, rate: float, sweeps: int = 1) -> SineSweep:
    """A sine sweep from a CSV with 'frequency [Hz]' and the peak 'amplitude' as an acceleration
    ('amplitude [g]') or a displacement ('amplitude [mm]'); ``rate`` in octaves per minute."""
    path = Path(path)
    f, a = _read_columns(path, {"frequency": [("Hz", "Hz")], "amplitude": [("g_n", "g"), ("mm", "mm")]}).values()
    _check_breakpoints(str(path), f.raw, a.raw, "sine amplitude", (f.unit, a.unit))
    if not rate > 0 or sweeps < 1:
        raise VibrationError(f"{path}: the sweep rate must be above 0 octave/min and the sweeps at least 1")
    return SineSweep(path.stem, f.si, a.si, "displacement" if a.kind == 1 else "acceleration", float(rate), int(sweeps))


def analysis_band(psd: Psd, sine: SineSweep | None = None) -> float:
    """The frequency [Hz] up to which modes are computed: twice the top of the inputs (a mode an
    octave above the band still adds to the response near the band's top; above it the static
    residual of the response takes over)."""
    return 2.0 * max(psd.f[-1], sine.f[-1] if sine is not None else 0.0)


def frequency_grid(f_lo: float, f_hi: float, f_modes, zetas, per_decade: int = 300, per_mode: int = 81) -> np.ndarray:
    """Frequencies [Hz] on which |H|^2 W is integrated by the trapezoid rule over [f_lo, f_hi].

    A log-spaced base grid, plus per mode in the band points f_r (1 + zeta_r tan(theta)) for
    uniformly spaced theta: a modal peak |1/(w_r^2 - w^2 + 2i zeta w_r w)|^2 is, to first order in
    zeta, constant per unit theta there, so the trapezoid rule resolves it with a few dozen points
    whatever the damping.
    """
    n = max(int(np.ceil(per_decade * np.log10(f_hi / f_lo))), 2)
    parts = [np.geomspace(f_lo, f_hi, n)]
    for fr, z in zip(np.atleast_1d(f_modes), np.atleast_1d(zetas)):
        span = np.arctan(min(0.5, 50.0 * z) / z)  # out to +-50 half-power bandwidths, at most +-50 %
        parts.append(fr * (1.0 + z * np.tan(np.linspace(-span, span, per_mode))))
    f = np.concatenate(parts)
    return np.unique(f[(f >= f_lo) & (f <= f_hi)])


def trapezoid_weights(f: np.ndarray) -> np.ndarray:
    """Weights w with sum(w * y) = the trapezoid-rule integral of y over the grid ``f``."""
    w = np.zeros_like(f)
    d = np.diff(f)
    w[:-1] += 0.5 * d
    w[1:] += 0.5 * d
    return w
