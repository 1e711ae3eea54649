"""``point_mass``: a lumped mass at a node (a transducer, a heavy part, a screw head), and its
optional rotary inertia about the two in-plane axes as a second, separate parameter
(``point_inertia``, reported as a point_mass). dM/dm puts 1 on the node's three translations;
dM/dJ is the unit rotary inertia of a body moving with the cells around the node (the footprint
of :func:`..fixtures.supports.mass_footprint`, as a board's [[masses]] entry of inertia alone);
dK = 0 (thesis eq. 3.11 with k = i and dK = 0 gives d lambda_i / dm = -lambda_i |phi_i(node)|^2)."""

from __future__ import annotations

import numpy as np

from ..fe import MassProperty
from ..fe.elements.discrete import mass_matrices
from ..fixtures.supports import mass_footprint
from .catalogue import Blocks, copy_model, node_candidates


class _Lumped:
    report_as = "point_mass"
    options = ("spacing",)
    lower = 0.0

    def __init__(self, name, param, unit, scale):
        self.name, self.param, self.unit, self.scale = name, param, unit, scale

    def generate(self, layout, spacing: float | None = None) -> list:
        return node_candidates(self.name, layout, spacing)

    def _cell(self, model, node: int) -> np.ndarray:
        if self.param == "mass":
            return np.array([node])
        shells = [(s.etype, s.conn) for s in model.sets.values() if s.etype in ("quad4", "tri3")]
        return mass_footprint(model.nodes, shells, node, 0.0, 1.0)[0]

    def _property(self, value: float):
        return MassProperty(value, (0.0, 0.0, 0.0)) if self.param == "mass" else MassProperty(0.0, (value, value, 0.0))

    def blocks(self, model, candidates) -> list:
        cells = [self._cell(model, int(c.nodes[0])) for c in candidates]
        out = []
        for size in sorted({c.size for c in cells}):
            idx = np.array([i for i, c in enumerate(cells) if c.size == size])
            conn = np.array([cells[i] for i in idx])
            Ke, Me = mass_matrices(model.nodes[conn], self._property(1.0))
            out.append(Blocks(conn, Ke, Me, idx))
        return out

    def apply(self, model, candidate, value: float):
        m = copy_model(model)
        m.add(f"effects.{candidate.name}", "mass", [self._cell(model, int(candidate.nodes[0]))], self._property(value))
        return m


MASS = _Lumped("point_mass", "mass", "kg", 1e-2)
INERTIA = _Lumped("point_inertia", "inertia", "kg*m^2", 1e-6)
