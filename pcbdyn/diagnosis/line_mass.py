"""``line_mass``: a mass m [kg] spread uniformly along a straight segment, lumped at nodes on the
three translations. Along a boundary (a connector, a cable clamp, a bracket along an edge) it lies on
the side's node chain, shared by tributary length; across the plate (a cable or a bar's mass,
:mod:`.mass_lines`) each piece of the line within a cell puts half its share at either end, spread
to the cell's nodes by the shape functions there. M is linear in m (weights summing to one), K does
not depend on it."""

from __future__ import annotations

import numpy as np

from ..board.effects import tributary_weights
from .catalogue import register, AlongSides, Candidate, SpreadMass
from .stiffener import label


class _LineMass(SpreadMass, AlongSides):
    name = report_as = "line_mass"
    param = "mass"
    unit = "kg"
    scale = 1e-2
    lower = 0.0

    def weights(self, model, candidate) -> np.ndarray:
        """Each node's share of the mass."""
        if "shares" in candidate.data:
            return candidate.data["shares"]
        return tributary_weights(model.nodes[candidate.nodes, :2])

    def across(self, layout, p0, p1):
        """The line mass along the straight segment ``p0``-``p1`` [m] across the plate, named for its
        ends; None where it misses the plate."""
        conn, W, ends = layout.line_cells(p0, p1)
        if not len(conn):
            return None
        share = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
        length = float(share.sum())
        nodes, at = np.unique(conn, return_inverse=True)
        at = at.reshape(conn.shape)
        w = np.zeros(nodes.size)
        np.add.at(w, at[:, :4], 0.5 * share[:, None] * W[:, 0, :4])
        np.add.at(w, at[:, 4:], 0.5 * share[:, None] * W[:, 1, 4:])
        keep = w > 1e-12 * length
        path = np.vstack([ends[:1, 0], ends[-1:, 1]])
        return Candidate(self.name, f"{self.name}@{label(path)}", tuple(path.mean(axis=0)), nodes[keep],
                         {"segment": path}, {"shares": w[keep] / w[keep].sum(), "length": length})

    def place(self, layout, candidate):
        if "shares" in candidate.data:
            c = self.across(layout, *candidate.geometry["segment"])
            if c is None:
                raise ValueError(f"{candidate.name}: its line misses the plate")
            return c
        return super().place(layout, candidate)


KIND = _LineMass()
register(KIND)
