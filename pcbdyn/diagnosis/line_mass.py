"""``line_mass``: a mass m [kg] spread uniformly along a boundary segment (a connector, a cable
clamp, a bracket along an edge), lumped at the segment's nodes by tributary length on the three
translations. M is linear in m (weights summing to one), K does not depend on it."""

from __future__ import annotations

import numpy as np

from ..board.effects import tributary_weights
from ..fe import MassProperty
from .catalogue import register, AlongSides, Blocks


class _LineMass(AlongSides):
    name = report_as = "line_mass"
    param = "mass"
    unit = "kg"
    scale = 1e-2
    lower = 0.0

    def blocks(self, model, candidates) -> list:
        nodes = np.concatenate([c.nodes for c in candidates])
        w = np.concatenate([tributary_weights(model.nodes[c.nodes, :2]) for c in candidates])
        Me = np.zeros((nodes.size, 6, 6))
        Me[:, [0, 1, 2], [0, 1, 2]] = w[:, None]
        owner = np.repeat(np.arange(len(candidates)), [c.nodes.size for c in candidates])
        return [Blocks(nodes[:, None], np.zeros_like(Me), Me, owner)]

    def apply(self, model, candidate, value: float):
        m = model.copy()
        for k, (n, w) in enumerate(zip(candidate.nodes, tributary_weights(model.nodes[candidate.nodes, :2]))):
            m.add(f"effects.{candidate.name}.{k}", "mass", [[int(n)]], MassProperty(value * w))
        return m


KIND = _LineMass()
register(KIND)
