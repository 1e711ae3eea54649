"""``ground_spring``: a translational spring to ground in z at a node (a standoff, screw or
component touching the board). dK/dk has a single 1 on the node's uz; dM = 0, so
d lambda_i / dk = phi_i(node, z)^2 (thesis eq. 3.11 with k = i). On a structure in 3-D (a box) the
spring acts along the shells' normal n at the node (``data["normal"]``): dK/dk = n n^T on its
translations. A spring at a point between nodes (:meth:`_GroundSpring.at_point`: a support placed from a measured
mode, :mod:`.support`) acts on the point that the shell cell's shape functions interpolate
(``data["point_weights"]`` over its nodes): dK/dk = (w w^T) (x) n n^T, the same point on any mesh."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..fe import SpringProperty
from ..fe.elements.discrete import point_spring
from ..fe.probe import model_probe
from .catalogue import register, Blocks, Candidate, node_candidates, on_nearest_node


class _GroundSpring:
    name = report_as = "ground_spring"
    param = "k"
    unit = "N/m"
    scale = 1e5
    lower = 0.0
    together = ("point_mass",)  # a bracket: a mass held by a spring at one point
    saturates = True  # stiffens the modes near it up to a pin (a clamp): :func:`.scan.saturated`
    options = ("spacing",)

    def generate(self, layout, spacing: float | None = None) -> list:
        out = node_candidates(self.name, layout, spacing)
        return out if layout.planar else [_normal(layout, c) for c in out]

    def place(self, layout, candidate):
        if candidate.between_nodes:
            return _at(layout, candidate.at)
        placed = on_nearest_node(layout, candidate)
        return placed if "normal" not in candidate.data else _normal(layout, placed)

    def at_point(self, layout, home, xy):
        """A spring to ground at the point ``xy`` [m] of a board between the nodes (interpolated by the shell
        cell that holds it; a point just past an edge on the edge, :meth:`.layout.Layout.onto_plate`); None
        off the board or on a structure in 3-D. ``home``: the candidate it moves from (the same call as
        :meth:`.point_mass._Lumped.at_point`)."""
        on = layout.onto_plate(xy) if layout.planar else None
        return None if on is None else _at(layout, on)

    def blocks(self, model, candidates) -> list:
        """A block per number of nodes: a spring at a node, or at a point between the nodes of an edge or a
        cell (the final walk of dev seed 8 put two such points beside the nodes' springs)."""
        groups: dict = {}
        for k, c in enumerate(candidates):
            groups.setdefault(c.nodes.size, []).append(k)
        out = []
        for _, group in sorted(groups.items()):
            conn = np.array([candidates[k].nodes for k in group], dtype=np.int64)
            Ke = np.array([_derivative(candidates[k]) for k in group])
            out.append(Blocks(conn, Ke, np.zeros_like(Ke), np.array(group)))
        return out

    def apply(self, model, candidate, value: float):
        m = model.copy()
        w = candidate.data.get("point_weights")
        m.add(f"effects.{candidate.name}", "spring", [candidate.nodes.tolist()],
              SpringProperty(k=value * _spring(candidate), weights=None if w is None else tuple(w)))
        return m


def _at(layout, xy) -> Candidate:
    """A spring to ground at the point ``xy`` [m] of a board (x, y), on the shell cell that holds it;
    :class:`..fe.probe.ProbeError` off the board."""
    z = float(layout.model.nodes[layout.shell_nodes()[0], 2])
    loc = model_probe(layout.model, [[xy[0], xy[1], z]]).location
    keep = loc.weights[0] != 0.0  # a triangle repeats its last node with weight 0
    nodes, weights = loc.nodes[0][keep], loc.weights[0][keep]
    return Candidate("ground_spring", f"ground_spring@x={1e3 * xy[0]:.4g}mm,y={1e3 * xy[1]:.4g}mm",
                     (float(xy[0]), float(xy[1])), nodes.astype(np.int64), data={"point_weights": tuple(weights.tolist())})


def _derivative(candidate) -> np.ndarray:
    """dK/dk on the candidate's nodes' DOFs: the spring's 6x6 at one node, (w w^T) (x) it at a point
    (the element's own matrix, :func:`pcbdyn.fe.elements.discrete.point_spring`)."""
    return point_spring(candidate.data.get("point_weights", (1.0,)), _spring(candidate))


def _spring(candidate) -> np.ndarray:
    """The 6x6 spring matrix per unit k: n n^T on the translations (z z^T on a board)."""
    n = np.asarray(candidate.data.get("normal", (0.0, 0.0, 1.0)), float)
    k = np.zeros((6, 6))
    k[:3, :3] = np.outer(n, n)
    return k


def _normal(layout, candidate):
    """``candidate`` acting along the shells' normal at its node."""
    return replace(candidate, data={**candidate.data, "normal": tuple(layout.normal(int(candidate.nodes[0])))})


KIND = _GroundSpring()
register(KIND)
