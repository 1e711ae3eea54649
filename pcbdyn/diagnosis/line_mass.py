"""``line_mass``: a mass m [kg] spread uniformly along a boundary segment (a connector, a cable
clamp, a bracket along an edge), lumped at the segment's nodes by tributary length on the three
translations. M is linear in m (weights summing to one), K does not depend on it."""

from __future__ import annotations

from ..board.effects import tributary_weights
from .catalogue import register, AlongSides, spread_mass_blocks, with_spread_mass


class _LineMass(AlongSides):
    name = report_as = "line_mass"
    param = "mass"
    unit = "kg"
    scale = 1e-2
    lower = 0.0

    def blocks(self, model, candidates) -> list:
        return spread_mass_blocks(candidates, [tributary_weights(model.nodes[c.nodes, :2]) for c in candidates])

    def apply(self, model, candidate, value: float):
        return with_spread_mass(model, candidate, tributary_weights(model.nodes[candidate.nodes, :2]), value)


KIND = _LineMass()
register(KIND)
