"""``ground_spring``: a translational spring to ground in z at a node (a standoff, screw or
component touching the board). dK/dk has a single 1 on the node's uz; dM = 0, so
d lambda_i / dk = phi_i(node, z)^2 (thesis eq. 3.11 with k = i)."""

from __future__ import annotations

import numpy as np

from ..fe import SpringProperty
from .catalogue import register, Blocks, copy_model, node_candidates, on_nearest_node


class _GroundSpring:
    name = report_as = "ground_spring"
    param = "k"
    unit = "N/m"
    scale = 1e5
    lower = 0.0
    options = ("spacing",)

    def generate(self, layout, spacing: float | None = None) -> list:
        return node_candidates(self.name, layout, spacing)

    def place(self, layout, candidate):
        return on_nearest_node(layout, candidate)

    def blocks(self, model, candidates) -> list:
        nodes = np.array([c.nodes[0] for c in candidates], dtype=np.int64)
        Ke = np.zeros((nodes.size, 6, 6))
        Ke[:, 2, 2] = 1.0
        return [Blocks(nodes[:, None], Ke, np.zeros_like(Ke), np.arange(nodes.size))]

    def apply(self, model, candidate, value: float):
        m = copy_model(model)
        m.add(f"effects.{candidate.name}", "spring", [[int(candidate.nodes[0])]],
              SpringProperty(k=(0.0, 0.0, value, 0.0, 0.0, 0.0)))
        return m


KIND = _GroundSpring()
register(KIND)
