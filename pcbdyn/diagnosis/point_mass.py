"""``point_mass``: a lumped mass at a node (a transducer, a heavy part, a screw head), and its
optional rotary inertia about the two in-plane axes as a second, separate parameter
(``point_inertia``, reported as a point_mass). dM/dm puts 1 on the node's three translations;
dM/dJ is the unit rotary inertia of a body moving with a disc of fixed size around the node (the
footprint of :func:`..fixtures.supports.mass_footprint`, as a board's [[masses]] entry of inertia
alone), so that it is the same effect on the finer meshes of the error budget.
A candidate with ``data["radius"]`` is one half of a body (:mod:`.bodies`): its mass or inertia
moves with the disc of that radius of gyration, as a [[masses]] entry with both (radius 0: a mass
placed from another mesh, at its point between the nodes). dK = 0 (thesis
eq. 3.11 with k = i and dK = 0 gives d lambda_i / dm = -lambda_i |phi_i(node)|^2)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..fe import MassProperty
from ..fe.elements.discrete import mass_matrices
from ..fe.model import SHELL_TYPES
from ..fixtures.supports import disc_footprints, footprint_radius
from .catalogue import register, Blocks, node_candidates, on_nearest_node


class _Lumped:
    report_as = "point_mass"
    options = ("spacing",)
    lower = 0.0

    def __init__(self, name, param, unit, scale):
        self.name, self.param, self.unit, self.scale = name, param, unit, scale

    def generate(self, layout, spacing: float | None = None) -> list:
        if self.param == "inertia" and not layout.planar:  # its axes are a plate's in-plane axes x, y
            return []
        return node_candidates(self.name, layout, spacing)

    def place(self, layout, candidate):
        """At ``candidate``'s point: a body keeps its centre and radius, a mass becomes a body of no
        size there (interpolated in the cell that holds the point, so that it sits where it sat on
        any mesh), an inertia goes on the nearest node (it turns with the disc around it)."""
        placed = on_nearest_node(layout, candidate)
        if "radius" in candidate.data:
            return replace(placed, at=candidate.at)
        if self.param == "mass":
            at = tuple(map(float, candidate.at))
            centre = at if len(at) == 3 else (*at, float(layout.model.nodes[placed.nodes[0], 2]))
            return replace(placed, at=candidate.at, data={**candidate.data, "radius": 0.0, "centre": centre})
        return placed

    def at_point(self, layout, home, xy):
        """A mass like candidate ``home`` at the point ``xy`` [m] of a plate between the nodes (a body of
        no size, :meth:`place`; a point just past an edge on the edge, :meth:`.layout.Layout.onto_plate`),
        named for its point; None where the point lies off the shell or the structure is in 3-D."""
        xy = layout.onto_plate(xy) if layout.planar else None
        if xy is None:
            return None
        plain = {k: v for k, v in home.data.items() if k not in ("radius", "centre")}
        c = self.place(layout, replace(home, at=(float(xy[0]), float(xy[1])), data=plain))
        try:
            self.footprint(layout.model, c)
        except ValueError:  # off the shell
            return None
        return replace(c, name=f"{self.name}@{1e3 * xy[0]:.2f},{1e3 * xy[1]:.2f}mm")

    def footprint(self, model, candidate) -> tuple:
        """(cell nodes, sample weights or None) the candidate's body moves with: with
        ``data["radius"]`` (a body of that radius of gyration centred at ``data["centre"]``,
        :mod:`.bodies`) the disc of :func:`..fixtures.supports.disc_footprint`, for its mass and
        its inertia alike; else its node for a mass and, for an inertia, the disc of an inertia
        alone around the node (:func:`..fixtures.supports.mass_footprint`)."""
        return self.footprints(model, [candidate])[0]

    def footprints(self, model, candidates) -> list:
        """:meth:`footprint` of each of ``candidates``, their discs located on the shell at once."""
        out: list = [None] * len(candidates)
        discs = []  # (index, centre, radius, first node)
        for i, c in enumerate(candidates):
            node = int(c.nodes[0])
            if "radius" in c.data:
                discs.append((i, c.data["centre"], float(c.data["radius"]), None))
            elif self.param == "mass":
                out[i] = (np.array([node]), None)
            else:
                discs.append((i, model.nodes[node], footprint_radius(0.0, 1.0), node))
        if discs:
            shells = [(s.etype, s.conn) for s in model.sets.values() if s.etype in SHELL_TYPES]
            idx, centres, radii, firsts = zip(*discs)
            for i, f in zip(idx, disc_footprints(model.nodes, shells, centres, radii, firsts)):
                out[i] = f
        return out

    def _property(self, value: float, weights=None):
        if self.param == "mass":
            return MassProperty(value, (0.0, 0.0, 0.0), footprint=weights)
        return MassProperty(0.0, (value, value, 0.0), footprint=weights)

    def blocks(self, model, candidates) -> list:
        cells = self.footprints(model, candidates)
        groups: dict = {}  # masses on their nodes share a block per size; a disc (a body, an inertia) has its own
        for i, (conn, W) in enumerate(cells):
            groups.setdefault(conn.size if W is None else -1 - i, []).append(i)
        out = []
        for _, idx in sorted(groups.items()):
            conn = np.array([cells[i][0] for i in idx])
            Ke, Me = mass_matrices(model.nodes[conn], self._property(1.0, cells[idx[0]][1]))
            out.append(Blocks(conn, Ke, Me, np.array(idx)))
        return out

    def apply(self, model, candidate, value: float):
        m = model.copy()
        conn, W = self.footprint(model, candidate)
        m.add(f"effects.{candidate.name}", "mass", [conn], self._property(value, W))
        return m


MASS = _Lumped("point_mass", "mass", "kg", 1e-2)
INERTIA = _Lumped("point_inertia", "inertia", "kg*m^2", 1e-6)
MASS.together = ("ground_spring", "point_inertia")  # a bracket: a mass held by a spring; a part: its inertia
INERTIA.together = ("point_mass",)
register(MASS, INERTIA)
