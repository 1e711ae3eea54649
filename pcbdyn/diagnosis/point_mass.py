"""``point_mass``: a lumped mass at a node (a transducer, a heavy part, a screw head), and its
optional rotary inertia about the two in-plane axes as a second, separate parameter
(``point_inertia``, reported as a point_mass). dM/dm puts 1 on the node's three translations,
dM/dJ on its rotations about x and y; dK = 0 (thesis eq. 3.11 with k = i and dK = 0 gives
d lambda_i / dm = -lambda_i |phi_i(node)|^2)."""

from __future__ import annotations

import numpy as np

from ..fe import MassProperty
from .catalogue import Blocks, copy_model, node_candidates


class _Lumped:
    report_as = "point_mass"
    options = ("spacing",)
    lower = 0.0

    def __init__(self, name, param, unit, scale, dofs):
        self.name, self.param, self.unit, self.scale, self.dofs = name, param, unit, scale, dofs

    def generate(self, layout, spacing: float | None = None) -> list:
        return node_candidates(self.name, layout, spacing)

    def blocks(self, model, candidates) -> list:
        nodes = np.array([c.nodes[0] for c in candidates], dtype=np.int64)
        Me = np.zeros((nodes.size, 6, 6))
        Me[:, self.dofs, self.dofs] = 1.0
        return [Blocks(nodes[:, None], np.zeros_like(Me), Me, np.arange(nodes.size))]

    def apply(self, model, candidate, value: float):
        m = copy_model(model)
        prop = MassProperty(value, (0.0, 0.0, 0.0)) if self.param == "mass" else MassProperty(0.0, (value, value, 0.0))
        m.add(f"effects.{candidate.name}", "mass", [[int(candidate.nodes[0])]], prop)
        return m


MASS = _Lumped("point_mass", "mass", "kg", 1e-2, [0, 1, 2])
INERTIA = _Lumped("point_inertia", "inertia", "kg*m^2", 1e-6, [3, 4])
