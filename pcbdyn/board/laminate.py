"""Board materials and stack-ups reduced to an equivalent plate by classical lamination theory.

Each layer is an isotropic sheet; a partly etched copper layer (``fill`` < 1) is mixed with the
surrounding resin by the rule of mixtures (stiffness and density in proportion to the area
fraction). The laminate's A (membrane), B (coupling) and D (bending) matrices are summed over the
layers about the mid-plane; the equivalent plate keeps A, the bending stiffness about the neutral
plane D - B A^-1 B, the mass per area and the rotary inertia, so an element kernel sees it exactly
like :class:`pcbdyn.fe.ShellProperty`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Typical isotropic properties (E [Pa], nu, rho [kg/m^3]) of board materials.
MATERIALS = {
    "copper": (117e9, 0.34, 8960.0),
    "FR4": (22e9, 0.15, 1850.0),
    "polyimide": (2.5e9, 0.34, 1420.0),
    "prepreg": (18e9, 0.15, 1800.0),
    "solder_mask": (3e9, 0.35, 1300.0),
}


@dataclass(frozen=True)
class Material:
    E: float
    nu: float
    rho: float


@dataclass(frozen=True)
class Layer:
    """``thickness`` [m] of ``material`` with area fraction ``fill`` (rest: ``filler``)."""

    thickness: float
    material: Material
    fill: float = 1.0
    filler: Material | None = None

    def mixed(self) -> Material:
        if self.fill >= 1.0 or self.filler is None:
            return self.material
        f, a, b = self.fill, self.material, self.filler
        return Material(f * a.E + (1 - f) * b.E, f * a.nu + (1 - f) * b.nu, f * a.rho + (1 - f) * b.rho)


def _plane_stress(m: Material) -> np.ndarray:
    c = m.E / (1.0 - m.nu**2)
    return c * np.array([[1.0, m.nu, 0.0], [m.nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - m.nu)]])


@dataclass(frozen=True)
class LaminateProperty:
    """Equivalent plate of a stack of layers (listed bottom to top); same interface as
    :class:`pcbdyn.fe.ShellProperty` (membrane, bending, shear, mass_per_area,
    rotary_inertia_per_area). ``nsm`` [kg/m^2] is extra smeared mass."""

    layers: tuple
    nsm: float = 0.0
    shear_factor: float = 5.0 / 6.0

    @property
    def t(self) -> float:
        return float(sum(L.thickness for L in self.layers))

    def _z(self):
        z = np.concatenate([[0.0], np.cumsum([L.thickness for L in self.layers])])
        return z - 0.5 * z[-1]

    def _abd(self):
        z = self._z()
        A = np.zeros((3, 3))
        B = np.zeros((3, 3))
        D = np.zeros((3, 3))
        for k, L in enumerate(self.layers):
            Q = _plane_stress(L.mixed())
            A += Q * (z[k + 1] - z[k])
            B += Q * (z[k + 1] ** 2 - z[k] ** 2) / 2.0
            D += Q * (z[k + 1] ** 3 - z[k] ** 3) / 3.0
        return A, B, D

    def membrane(self) -> np.ndarray:
        return self._abd()[0]

    def bending(self) -> np.ndarray:
        """Bending stiffness about the neutral plane, D - B A^-1 B (B = 0 for a symmetric stack)."""
        A, B, D = self._abd()
        return D - B @ np.linalg.solve(A, B)

    def shear(self) -> np.ndarray:
        G = sum(L.mixed().E / (2.0 * (1.0 + L.mixed().nu)) * L.thickness for L in self.layers)
        return self.shear_factor * G * np.eye(2)

    def mass_per_area(self) -> float:
        return float(sum(L.mixed().rho * L.thickness for L in self.layers)) + self.nsm

    def rotary_inertia_per_area(self) -> float:
        z = self._z()
        return float(sum(L.mixed().rho * (z[k + 1] ** 3 - z[k] ** 3) / 3.0 for k, L in enumerate(self.layers)))

    def equivalent_isotropic(self) -> tuple[float, float]:
        """(E, nu) of the homogeneous plate of the same thickness with the same bending stiffness."""
        D = self.bending()
        nu = D[0, 1] / D[0, 0]
        E = 12.0 * D[0, 0] * (1.0 - nu**2) / self.t**3
        return float(E), float(nu)
