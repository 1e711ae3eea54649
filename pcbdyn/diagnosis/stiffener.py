"""``stiffener``: a rib along a straight path of nodes (a metal bar, a heat sink, a frame member
bonded to the board), a beam whose axis is offset by (t + h) / 2 above the mid-surface.

The parameter is its bending stiffness EI [N m^2] about the axis parallel to the board. To keep
K and M linear in it, the rib has a fixed material and height h and only its width b varies
(EI = E b h^3 / 12): area A = b h, Iy = Iz = b h^3 / 12 (its in-plane bending is negligible next
to the board's membrane stiffness), J = b h^3 / 3 (thin strip), mass rho b h; every term is
proportional to b, hence to EI. Defaults: aluminium (70 GPa, 2700 kg/m^3), h = 4 mm.
"""

from __future__ import annotations

import numpy as np

from ..board.effects import rib_property
from ..board.spec import RibSection
from ..fe.elements import kernel
from .catalogue import Blocks, chain_candidate, copy_model


class _Stiffener:
    name = report_as = "stiffener"
    param = "EI"
    unit = "N*m^2"
    scale = 1.0
    lower = 0.0
    options = ("path_spacing",)

    def __init__(self, section: RibSection = RibSection()):
        self.section = section

    def generate(self, layout, path_spacing: float = 0.02) -> list:
        """Full-span rows (along x) and columns (along y) of nodes every ``path_spacing`` [m]."""
        if not path_spacing > 0:
            raise ValueError(f"path_spacing must be > 0 m, got {path_spacing}")
        xy = layout.xy[layout.shell_nodes()]
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        out = []
        for axis, label in ((1, "y"), (0, "x")):
            n = max(1, int(round((hi[axis] - lo[axis]) / path_spacing)))
            for v in lo[axis] + (np.arange(n) + 0.5) * (hi[axis] - lo[axis]) / n:
                p0, p1 = lo.copy(), hi.copy()
                p0[axis] = p1[axis] = v
                chain = layout.node_path(p0, p1)
                if chain.size > 1:
                    c = chain_candidate(self.name, layout, f"{label}={1e3 * v:.4g}mm", chain, key="path")
                    c.data["thickness"] = layout.thickness
                    out.append(c)
        return out

    def blocks(self, model, candidates) -> list:
        out = []
        thick = np.array([c.data["thickness"] for c in candidates])
        for t in np.unique(thick):  # one kernel call per plate thickness (it sets the offset)
            ks = np.flatnonzero(thick == t)
            edges = [candidates[k].data["edges"] for k in ks]
            conn = np.concatenate(edges)
            Ke, Me = kernel("beam2")(model.nodes[conn], rib_property(1.0, t, self.section))
            out.append(Blocks(conn, Ke, Me, np.repeat(ks, [e.shape[0] for e in edges])))
        return out

    def apply(self, model, candidate, value: float):
        if not value > 0:
            raise ValueError(f"{candidate.name}: a stiffener's EI must be > 0 N m^2, got {value}")
        m = copy_model(model)
        m.add(f"effects.{candidate.name}", "beam2", candidate.data["edges"],
              rib_property(value, candidate.data["thickness"], self.section))
        return m


KIND = _Stiffener()
