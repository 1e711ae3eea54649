"""``edge_stiffness``: a rotational stiffness kr per unit length about a segment of an edge or
support line [N m/rad/m] (one card guide, or one part of it, tighter than assumed; a free edge
touching a frame). It is an edge-spring set on the segment's element edges (consistent
distribution, thesis section 7.4); K is linear in kr, M does not depend on it.

A positive value only: the edge-spring kernel rejects negative springs, so a guide softer than
declared needs its declared k_rot split per segment (a board-model parameter), not this effect.
"""

from __future__ import annotations

import numpy as np

from ..board.effects import edge_spring_property
from ..fe.elements import kernel
from .catalogue import register, AlongSides, Blocks


class _EdgeStiffness(AlongSides):
    name = report_as = "edge_stiffness"
    param = "k_rot"
    unit = "N*m/rad/m"
    scale = 1e3
    lower = 0.0
    saturates = True  # stiffens the modes near it up to a pin (a clamp): :func:`.scan.saturated`

    def blocks(self, model, candidates) -> list:
        edges = [c.data["edges"] for c in candidates]
        conn = np.concatenate(edges)
        Ke, Me = kernel("edge_spring")(model.nodes[conn], edge_spring_property(1.0))
        return [Blocks(conn, Ke, Me, np.repeat(np.arange(len(edges)), [e.shape[0] for e in edges]))]

    def apply(self, model, candidate, value: float):
        m = model.copy()
        m.add(f"effects.{candidate.name}", "edge_spring", candidate.data["edges"], edge_spring_property(value))
        return m


KIND = _EdgeStiffness()
register(KIND)
