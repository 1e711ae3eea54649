"""Modal damping for the response: Steinberg's transmissibility Q = sqrt(f_n) (the default for
printed circuit boards), a ratio or a Q for every mode, or the ratios identified in a modal test
(UFF dataset 55) given to the model modes they pair with by MAC.

Viscous modal damping: zeta = 1 / (2 Q). Steinberg's Q = sqrt(f_n) is his rule of thumb for
plug-in boards at resonance (D. S. Steinberg, Vibration Analysis for Electronic Equipment, 3rd ed.,
Wiley 2000, eqs. 8.10 and 9.52); model modes with no test partner keep it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .spectra import VibrationError

USAGE = "--damping takes 'steinberg' (Q = sqrt(f_n), the default), 'zeta=0.05', 'Q=10' or a UFF file of test modes"


@dataclass(frozen=True)
class Damping:
    """What ``--damping`` asked for: ``kind`` steinberg | zeta | Q | uff, with its value or file."""

    kind: str
    value: float | None = None
    path: Path | None = None

    def describe(self) -> str:
        if self.kind == "steinberg":
            return "Steinberg, Q = sqrt(f_n)"
        if self.kind == "uff":
            return f"identified in {self.path} (Steinberg's Q = sqrt(f_n) for unpaired modes)"
        return f"{self.kind} = {self.value:g} for every mode"


def parse_damping(text: str | None) -> Damping:
    """``--damping`` text -> :class:`Damping`, with a usage message for anything else."""
    t = (text or "steinberg").strip()
    if t.lower() == "steinberg":
        return Damping("steinberg")
    key, sep, val = t.partition("=")
    if sep and key.strip().lower() in ("zeta", "q"):
        try:
            v = float(val)
        except ValueError:
            raise VibrationError(f"--damping '{t}': '{val}' is not a number; {USAGE}") from None
        kind = "zeta" if key.strip().lower() == "zeta" else "Q"
        if not (0 < v < 1 if kind == "zeta" else v > 0.5):
            raise VibrationError(f"--damping '{t}': zeta must lie in (0, 1) and Q above 0.5; {USAGE}")
        return Damping(kind, v)
    path = Path(t)
    if path.is_file():
        return Damping("uff", path=path)
    raise VibrationError(f"--damping '{t}' is not understood (no such file either); {USAGE}")


def steinberg_zeta(freqs) -> np.ndarray:
    """zeta = 1 / (2 sqrt(f_n)) for f_n in Hz."""
    return 0.5 / np.sqrt(np.asarray(freqs, dtype=float))


def modal_damping(damping: Damping, model, modes, tol: float | None = None) -> tuple:
    """(zeta per elastic mode, where each came from) for the model ``modes``; ``tol`` [m]: how far
    off the shells a test point may lie (default: :func:`pcbdyn.fe.probe.locate`'s).

    With a UFF file, the test modes are paired with the model modes by MAC (read through the shell
    shape functions at the test points, :func:`pcbdyn.correlation.correlate`); each paired model
    mode takes its test mode's damping ratio, the others Steinberg's.
    """
    f = modes.frequencies
    if damping.kind == "zeta":
        return np.full(f.size, damping.value), ["zeta option"] * f.size
    if damping.kind == "Q":
        return np.full(f.size, 0.5 / damping.value), ["Q option"] * f.size
    zeta = steinberg_zeta(f)
    source = ["steinberg Q = sqrt(f)"] * f.size
    if damping.kind == "uff":
        from ..correlation import correlate
        from ..fe import ModelError
        from ..testdata import TestDataError, read_uff

        data = read_uff(damping.path)
        test = data.modes
        if test is None or test.n_modes == 0:
            raise VibrationError(f"{damping.path}: no mode shapes (UFF dataset 55) to take damping from; {USAGE}")
        if not np.any(test.damping > 0):
            raise VibrationError(f"{damping.path}: every damping ratio in the file is 0; export the identified "
                                 "modal damping with the shapes, or give --damping zeta=... or Q=...")
        try:
            pairs = [p for p in correlate(test, model, modes, tol=tol).pairing.pairs if p.used]
        except (ModelError, TestDataError) as exc:
            raise VibrationError(f"{damping.path}: the test points do not lie on the model: {exc}") from None
        if not pairs:
            raise VibrationError(f"{damping.path}: no test mode pairs with a model mode (MAC < 0.5); check that "
                                 "the test is of this board and configuration")
        for p in pairs:
            if test.damping[p.test] > 0:
                zeta[p.model] = test.damping[p.test]
                source[p.model] = f"test mode {p.test + 1} (MAC {p.mac_combined:.2f})"
    return zeta, source
