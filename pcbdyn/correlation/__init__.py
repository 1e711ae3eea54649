"""Correlation of test and model: MAC/COMAC/FRAC/FDAC, mode pairing, orthogonality, expansion."""

from .mac import automac, comac, mac
from .frf import fdac, frac
from .pairing import Pair, Pairing, pair_modes, subspace_mac
from .correlate import Correlation, correlate
from .orthogonality import cross_orthogonality, mixed_orthogonality, off_diagonal_ratio, rigid_translation, static_mass

__all__ = [
    "Correlation", "correlate", "mac", "automac", "comac", "frac", "fdac",
    "Pair", "Pairing", "pair_modes", "subspace_mac",
    "cross_orthogonality", "mixed_orthogonality", "off_diagonal_ratio", "rigid_translation", "static_mass",
]
