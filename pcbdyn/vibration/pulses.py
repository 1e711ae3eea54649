"""Shock inputs: classical pulses written as text ("half-sine 1500 g 0.5 ms"), acceleration records
and shock response spectra read from CSV files with units in the header.

A pulse or record is kept as a piecewise-linear acceleration (times, values), which the response
integrates exactly (:mod:`.transient`): a terminal-peak sawtooth and a trapezoid are piecewise
linear already (the sawtooth's drop is a jump: two values at one time); a half-sine is sampled at
``HALF_SINE_SEGMENTS`` chords, whose area is short of the sine's by (pi/n)^2/12 (5e-6 at n = 400).
Pulse shapes as MIL-STD-810H method 516.8 draws them. SI inside (m/s^2, s, Hz).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..units import UnitError, to_si
from .spectra import G, VibrationError, _check_breakpoints, _read_columns, loglog

#: chords of a half-sine pulse
HALF_SINE_SEGMENTS = 400
#: rise and fall of a trapezoid, as a fraction of its duration, when the text gives none
TRAPEZOID_EDGE = 0.1
#: pulse names accepted -> the kind
KINDS = {"half-sine": "half-sine", "halfsine": "half-sine", "sawtooth": "sawtooth", "terminal-peak-sawtooth": "sawtooth",
         "terminal-peak sawtooth": "sawtooth", "tps": "sawtooth", "trapezoid": "trapezoid", "trapezoidal": "trapezoid"}
PULSE_USAGE = ("--pulse takes '<shape> <peak> <duration>' with units, e.g. 'half-sine 1500 g 0.5 ms', "
               "'sawtooth 100 g 6 ms' (terminal peak) or 'trapezoid 50 g 11 ms rise 1 ms fall 1 ms'")
_NUMBER = re.compile(r"^[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?$")
_NUMBER_UNIT = re.compile(r"^([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)([A-Za-z].*)$")


@dataclass(frozen=True)
class Transient:
    """A base acceleration history: piecewise linear through (``t`` [s], ``a`` [m/s^2]), zero after
    its last point; ``kind`` half-sine | sawtooth | trapezoid | history."""

    kind: str
    name: str
    source: str
    t: np.ndarray
    a: np.ndarray

    @property
    def peak(self) -> float:
        return float(np.abs(self.a).max())

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    def describe(self) -> str:
        if self.kind == "history":
            return f"record {self.name}: {self.t.size} samples over {self.duration * 1e3:.4g} ms, peak {self.peak / G:.4g} g"
        return f"{self.name} ({self.source})"


@dataclass(frozen=True)
class SrsSpec:
    """A shock response spectrum to meet: breakpoints ``f`` [Hz], ``value`` [m/s^2] (maximax
    absolute acceleration), log-log in between, for oscillators of quality factor ``q``."""

    name: str
    source: str
    f: np.ndarray
    value: np.ndarray
    q: float
    kind: str = "srs"
    duration: float | None = None

    @property
    def peak(self) -> float:
        return float(self.value.max())

    def at(self, freqs) -> np.ndarray:
        """The spectrum at ``freqs`` [Hz], held at its end values outside its band."""
        return loglog(np.clip(freqs, self.f[0], self.f[-1]), self.f, self.value)

    def describe(self) -> str:
        return (f"SRS {self.name}: {self.f[0]:g}-{self.f[-1]:g} Hz, up to {self.peak / G:.4g} g, Q = {self.q:g} "
                f"({self.source})")


def _quantities(text: str, words: list) -> list:
    """[(keyword or None, number text, unit text or None)] of the pulse text after its shape."""
    out, i = [], 0
    while i < len(words):
        key = None
        if words[i].lower() in ("rise", "fall"):
            key, i = words[i].lower(), i + 1
            if i == len(words):
                raise VibrationError(f"--pulse '{text}': '{key}' is not followed by a time; {PULSE_USAGE}")
        m = _NUMBER_UNIT.match(words[i])
        if m:
            out.append((key, m.group(1), m.group(2)))
            i += 1
        elif _NUMBER.match(words[i]):
            unit = words[i + 1] if i + 1 < len(words) and words[i + 1].lower() not in ("rise", "fall") \
                and not _NUMBER.match(words[i + 1]) else None
            out.append((key, words[i], unit))
            i += 2 if unit else 1
        else:
            raise VibrationError(f"--pulse '{text}': '{words[i]}' is not a quantity; {PULSE_USAGE}")
    return out


def _si(text: str, what: str, number: str, unit: str | None, expected: str, example: str) -> float:
    if unit is None:
        raise VibrationError(f"--pulse '{text}': the {what} '{number}' has no unit; write it with one, e.g. "
                             f"'{number} {example}' ({PULSE_USAGE})")
    try:
        value = to_si(f"{number} {unit}", expected, f"--pulse '{text}': the {what}")
    except UnitError as exc:
        raise VibrationError(f"{exc}; {PULSE_USAGE}") from None
    if not value > 0:
        raise VibrationError(f"--pulse '{text}': the {what} {number} {unit} must be above 0 (a pulse along the "
                             f"negative axis gives the same peaks); {PULSE_USAGE}")
    return value


def parse_pulse(text: str) -> Transient:
    """``--pulse`` text -> :class:`Transient` (see :data:`PULSE_USAGE`)."""
    words = str(text).split()
    k = next((i for i, w in enumerate(words) if _NUMBER.match(w) or _NUMBER_UNIT.match(w)), len(words))
    shape = " ".join(words[:k]).lower()
    if shape not in KINDS:
        raise VibrationError(f"--pulse '{text}': unknown shape '{shape}' (half-sine, sawtooth, trapezoid); {PULSE_USAGE}")
    kind = KINDS[shape]
    q = _quantities(text, words[k:])
    plain = [x for x in q if x[0] is None]
    if len(plain) != 2 or (kind != "trapezoid" and len(q) != 2):
        raise VibrationError(f"--pulse '{text}': expected a peak and a duration"
                             f"{' (and rise, fall)' if kind == 'trapezoid' else ''}; {PULSE_USAGE}")
    peak = _si(text, "peak", plain[0][1], plain[0][2], "m/s^2", "g")
    duration = _si(text, "duration", plain[1][1], plain[1][2], "s", "ms")
    label = f"{kind} {peak / G:.4g} g {duration * 1e3:.4g} ms"
    if kind == "half-sine":
        t = np.linspace(0.0, duration, HALF_SINE_SEGMENTS + 1)
        return Transient(kind, label, f"half-sine sampled at {HALF_SINE_SEGMENTS} chords", t,
                         peak * np.sin(np.pi * t / duration))
    if kind == "sawtooth":
        return Transient(kind, label, "terminal-peak sawtooth, ideal drop", np.array([0.0, duration, duration]),
                         np.array([0.0, peak, 0.0]))
    edges = {key: _si(text, key, n, u, "s", "ms") for key, n, u in q if key}
    rise = edges.get("rise", TRAPEZOID_EDGE * duration)
    fall = edges.get("fall", rise)
    if rise + fall > duration:
        raise VibrationError(f"--pulse '{text}': rise and fall ({(rise + fall) * 1e3:g} ms) exceed the duration "
                             f"({duration * 1e3:g} ms); {PULSE_USAGE}")
    return Transient(kind, label, f"trapezoid, rise {rise * 1e3:.4g} ms, fall {fall * 1e3:.4g} ms",
                     np.array([0.0, rise, duration - fall, duration]), np.array([0.0, peak, peak, 0.0]))


def read_history(path) -> Transient:
    """An acceleration record from a CSV with columns 'time [s]' and 'acceleration [g]' (any units of
    those kinds), times increasing."""
    path = Path(path)
    t, a = _read_columns(path, {"time": [("s", "s")], "acceleration": [("m/s^2", "g")]}).values()
    if t.si.size < 2:
        raise VibrationError(f"{path}: a record needs at least two samples (time, acceleration)")
    down = np.flatnonzero(np.diff(t.si) <= 0)
    if down.size:
        i = down[0] + 1
        raise VibrationError(f"{path}: data row {i + 1}: time {t.raw[i]:g} {t.unit} does not rise above the row "
                             f"before ({t.raw[i - 1]:g} {t.unit}); sort the rows by increasing time, each time once")
    return Transient("history", path.name, str(path), t.si, a.si)


def read_srs(path, q: float) -> SrsSpec:
    """A shock response spectrum from a CSV with columns 'frequency [Hz]' and 'acceleration [g]'."""
    path = Path(path)
    f, v = _read_columns(path, {"frequency": [("Hz", "Hz")], "acceleration": [("m/s^2", "g")]}).values()
    _check_breakpoints(str(path), f.raw, v.raw, "SRS", (f.unit, v.unit))
    return SrsSpec(path.stem, str(path), f.si, v.si, float(q))
