"""``region_mass``: a mass m [kg] spread uniformly over a region of the board (a heat sink, a shield
can, a potted block: a body glued over an area, whose mass moves with the plate under it and whose
stiffness is the region's stiffness change, :mod:`.region_stiffness`). The mass is lumped at the
region's nodes by their tributary area (each cell's area shared equally by its corners) on the three
translations, as a board's ``[[regions]]`` entry with a ``mass`` builds it; M is linear in m (weights
summing to one), K does not depend on it.

Candidates: the regions of :mod:`.region_stiffness` (patches of two sizes and the parts' footprints),
on a board only: on a housing those regions are whole plates, whose mass is a declared density.
"""

from __future__ import annotations

import numpy as np

from ..board.effects import area_weights
from .catalogue import register, SpreadMass
from .region_stiffness import _RegionStiffness


class _RegionMass(SpreadMass, _RegionStiffness):
    name = report_as = "region_mass"
    uses_properties = False
    param = "mass"
    unit = "kg"
    scale = 1e-2
    lower = 0.0
    together = ("region_stiffness",)
    joint = None  # masses over one area add and stay >= 0: no test taken together

    def generate(self, layout, patch: float = 0.02) -> list:
        return super().generate(layout, patch) if layout.planar else []

    @staticmethod
    def moved_value(old, new, value: float) -> float:
        """A mass moved to another region (a step of the local search) starts at the same mass (the
        catalogue's default, restated: the stiffness change this kind inherits from scales by area)."""
        return value

    @staticmethod
    def weights(model, candidate) -> np.ndarray:
        """The share of the mass at each of ``candidate.nodes`` (sum 1)."""
        return area_weights(model.nodes[:, :2], list(candidate.data["cells"].values()), candidate.nodes)


KIND = _RegionMass()
register(KIND)
