"""``ground_spring``: a translational spring to ground in z at a node (a standoff, screw or
component touching the board). dK/dk has a single 1 on the node's uz; dM = 0, so
d lambda_i / dk = phi_i(node, z)^2 (thesis eq. 3.11 with k = i). On a structure in 3-D (a box) the
spring acts along the shells' normal n at the node (``data["normal"]``): dK/dk = n n^T on its
translations."""

from __future__ import annotations

from dataclasses import replace

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
        out = node_candidates(self.name, layout, spacing)
        return out if layout.planar else [_normal(layout, c) for c in out]

    def place(self, layout, candidate):
        placed = on_nearest_node(layout, candidate)
        return placed if "normal" not in candidate.data else _normal(layout, placed)

    def blocks(self, model, candidates) -> list:
        nodes = np.array([c.nodes[0] for c in candidates], dtype=np.int64)
        Ke = np.zeros((nodes.size, 6, 6))
        Ke[:, :3, :3] = [_unit(c) for c in candidates]
        return [Blocks(nodes[:, None], Ke, np.zeros_like(Ke), np.arange(nodes.size))]

    def apply(self, model, candidate, value: float):
        m = copy_model(model)
        k = np.zeros((6, 6))
        k[:3, :3] = value * _unit(candidate)
        m.add(f"effects.{candidate.name}", "spring", [[int(candidate.nodes[0])]], SpringProperty(k=k))
        return m


def _unit(candidate) -> np.ndarray:
    """dK/dk on the translations: n n^T (z z^T on a board)."""
    n = np.asarray(candidate.data.get("normal", (0.0, 0.0, 1.0)), float)
    return np.outer(n, n)


def _normal(layout, candidate):
    """``candidate`` acting along the shells' normal at its node."""
    return replace(candidate, data={**candidate.data, "normal": tuple(layout.normal(int(candidate.nodes[0])))})


KIND = _GroundSpring()
register(KIND)
