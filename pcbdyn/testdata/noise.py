"""Measurement noise for simulated tests, the thesis' uniform multiplicative models (eq. 5.72-5.74):
the one noise model of pcbdyn (simulated tests, calibration and localisation studies use it).

Each value is multiplied by (1 + p/100 * eps) with eps uniform in [-1, 1], drawn independently per
frequency (eq. 5.72), per shape component (eq. 5.73) or per FRF value (eq. 5.74). p is a percentage.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def add_noise(values, pct: float, seed=None, name: str = "the") -> np.ndarray:
    """Measurement noise of a simulated test: values (1 + p/100 eps), eps uniform in [-1, 1] drawn
    per component (thesis eqs. 5.72-5.74).

    Parameters
    ----------
    values : array_like
        Frequencies, shape components or FRF values; complex values (FRFs) get a real factor, as in
        eq. 5.74.
    pct : float
        The noise level p [%], at least 0.
    seed : int or numpy.random.Generator, optional
        A Generator is drawn from (so that successive calls differ); a seed makes the draw repeatable.
    name : str
        The quantity, named in the error a negative ``pct`` raises.

    Returns
    -------
    numpy.ndarray
        The noisy values, of the shape of ``values``.

    Examples
    --------
    >>> f = add_noise([100.0, 200.0, 300.0], 1.0, seed=0)
    >>> bool(abs(f / [100.0, 200.0, 300.0] - 1).max() <= 0.01)
    True
    >>> bool((add_noise([100.0], 1.0, seed=0) == f[:1]).all())
    True
    """
    if pct < 0:
        raise ValueError(f"{name} noise level must be a non-negative percentage, got {pct}")
    v = np.asarray(values)
    eps = np.random.default_rng(seed).uniform(-1.0, 1.0, size=v.shape)
    return (1.0 + pct / 100.0 * eps) * v


def noisy_frequencies(f, pct: float, seed=None) -> np.ndarray:
    """f_i (1 + p/100 eps_i) (thesis eq. 5.72)."""
    return add_noise(f, pct, seed, "frequency")


def noisy_shapes(phi, pct: float, seed=None) -> np.ndarray:
    """phi_ij (1 + p/100 eps_ij) for every DOF i and mode j (thesis eq. 5.73)."""
    return add_noise(phi, pct, seed, "mode shape")


def noisy_frfs(H, pct: float, seed=None) -> np.ndarray:
    """H_ij(w_k) (1 + p/100 eps_ijk), eps real, for every FRF and frequency line (thesis eq. 5.74)."""
    return add_noise(H, pct, seed, "FRF")


@dataclass(frozen=True)
class Noise:
    """Noise levels in percent for frequencies, mode shapes and FRFs (thesis eq. 5.72-5.74).

    Examples
    --------
    >>> Noise.parse("f=0.2,shape=2")
    Noise(frequency_pct=0.2, shape_pct=2.0, frf_pct=0.0)
    >>> Noise.parse("1")
    Noise(frequency_pct=1.0, shape_pct=1.0, frf_pct=1.0)
    """

    frequency_pct: float = 0.0
    shape_pct: float = 0.0
    frf_pct: float = 0.0

    @classmethod
    def parse(cls, text: str) -> "Noise":
        """From "f=0.5,shape=2,frf=1" or one number for all three (as a CLI option gives it)."""
        text = str(text).strip()
        try:
            if "=" not in text:
                p = float(text)
                return cls(p, p, p)
            names = {"f": "frequency_pct", "freq": "frequency_pct", "frequency": "frequency_pct",
                     "shape": "shape_pct", "phi": "shape_pct", "frf": "frf_pct", "h": "frf_pct"}
            kw = {}
            for item in text.split(","):
                k, v = item.split("=")
                kw[names[k.strip().lower()]] = float(v)
            return cls(**kw)
        except (KeyError, ValueError):
            raise ValueError(
                f"noise '{text}' is not understood: give a percentage for all (e.g. 1) or "
                "'f=0.5,shape=2,frf=1'"
            ) from None
