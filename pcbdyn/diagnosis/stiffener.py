"""``stiffener``: a rib along a straight line (a metal bar, a heat sink, a frame member bonded to
the board), a beam whose axis is offset by (t + h) / 2 above the mid-surface, embedded in the
shell (:mod:`..fe.elements.embedded_beam`): its pieces end where the line crosses the cells'
edges, so it runs straight whatever the mesh: a beam on a row of nodes of an unstructured mesh
zig-zags, and a zig-zag rib is not the straight one the data come from (where a row of nodes does
follow the line, the pieces end on its nodes: a beam on that row).

The parameter is its bending stiffness EI [N m^2] about the axis parallel to the board. To keep
K and M linear in it, the rib has a fixed material and height h and only its width b varies
(EI = E b h^3 / 12): area A = b h, Iy = Iz = b h^3 / 12 (its in-plane bending is negligible next
to the board's membrane stiffness), J = b h^3 / 3 (thin strip), mass rho b h; every term is
proportional to b, hence to EI. Defaults: aluminium (70 GPa, 2700 kg/m^3), h = 4 mm.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..board.effects import rib_property
from ..board.entries import RibSection
from ..fe import EmbeddedBeamProperty
from ..fe.elements import kernel
from .catalogue import register, Blocks, Candidate, copy_model


class _Stiffener:
    name = report_as = "stiffener"
    param = "EI"
    unit = "N*m^2"
    scale = 1.0
    lower = 0.0
    options = ("path_spacing",)
    reanalysed = False  # a rib changes the modes beyond a first-order basis (:mod:`.scan`)

    def __init__(self, section: RibSection = RibSection()):
        self.section = section

    def generate(self, layout, path_spacing: float = 0.02) -> list:
        """Full-span rows (along x) and columns (along y) every ``path_spacing`` [m]."""
        if not path_spacing > 0:
            raise ValueError(f"path_spacing must be > 0 m, got {path_spacing}")
        if not layout.planar:  # rows and columns of a plate in one plane only
            return []
        lo, hi = _extent(layout)
        out = []
        for axis in (1, 0):
            n = max(1, int(round((hi[axis] - lo[axis]) / path_spacing)))
            out += self._lines(layout, axis, lo[axis] + (np.arange(n) + 0.5) * (hi[axis] - lo[axis]) / n)
        return out

    def parallel(self, layout, candidate, offsets) -> list:
        """Full-span lines parallel to ``candidate`` (a row or column of :meth:`generate`), moved
        across by ``offsets`` [m]: finer places around a rib found on the first grid."""
        path = np.asarray(candidate.geometry["path"], float)
        axis = line_axis(path)
        return self._lines(layout, axis, path[0, axis] + np.asarray(offsets, float))

    def along(self, candidate, path):
        """``candidate`` on the full-span straight line ``path`` (2, 2) [m] instead, named for it (a
        rib moved to where another mesh, on which it is placed (:meth:`place`), follows it)."""
        path = np.asarray(path, float)[[0, -1]]
        axis = line_axis(path)
        return replace(candidate, name=f"{self.name}@{_label(axis, path[0, axis])}", at=tuple(path.mean(axis=0)),
                       geometry={**candidate.geometry, "path": path})

    def _lines(self, layout, axis: int, values) -> list:
        """Full-span lines x = v (``axis`` 0) or y = v (1) that cross the plate."""
        lo, hi = _extent(layout)
        out = []
        for v in values:
            p0, p1 = lo.copy(), hi.copy()
            p0[axis] = p1[axis] = v
            c = self.candidate(layout, _label(axis, v), p0, p1)
            if c is not None:
                out.append(c)
        return out

    def candidate(self, layout, label: str, p0, p1):
        """The rib along the straight line ``p0``-``p1`` [m] (None where it misses the plate)."""
        conn, weights, ends = layout.line_cells(p0, p1)
        if not len(conn):
            return None
        pts = np.vstack([ends[:1, 0], ends[:, 1]])
        length = float(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).sum())
        return Candidate(self.name, f"{self.name}@{label}", tuple(0.5 * (pts[0] + pts[-1])), np.unique(conn),
                         {"path": pts[[0, -1]]},
                         {"conn": conn, "weights": weights, "length": length, "thickness": layout.thickness})

    def place(self, layout, candidate):
        """Along ``candidate``'s line (ValueError where it misses the plate)."""
        c = self.candidate(layout, "placed", *candidate.geometry["path"])
        if c is None:
            raise ValueError(f"{candidate.name}: its line misses the plate")
        return c

    def _property(self, value: float, candidate):
        return EmbeddedBeamProperty(rib_property(value, candidate.data["thickness"], self.section),
                                    candidate.data["weights"])

    def blocks(self, model, candidates) -> list:
        out = []
        for k, c in enumerate(candidates):
            conn = c.data["conn"]
            Ke, Me = kernel("embedded_beam2")(model.nodes[conn], self._property(1.0, c))
            out.append(Blocks(conn, Ke, Me, np.full(len(conn), k)))
        return out

    def apply(self, model, candidate, value: float):
        if not value > 0:
            raise ValueError(f"{candidate.name}: a stiffener's EI must be > 0 N m^2, got {value}")
        m = copy_model(model)
        m.add(f"effects.{candidate.name}", "embedded_beam2", candidate.data["conn"], self._property(value, candidate))
        return m


def line_axis(path) -> int:
    """0 for a column (x constant along ``path``), 1 for a row (y constant)."""
    (x0, y0), (x1, y1) = np.asarray(path, float)[[0, -1]]
    return 0 if abs(x1 - x0) < abs(y1 - y0) else 1


def _label(axis: int, v: float) -> str:
    """The name of the row or column at ``v`` [m]: ``x=<mm>mm`` (``axis`` 0) or ``y=<mm>mm``."""
    return f"{'xy'[axis]}={1e3 * v:.4g}mm"


def _extent(layout):
    xy = layout.xy[layout.shell_nodes()]
    return xy.min(axis=0), xy.max(axis=0)


KIND = _Stiffener()
register(KIND)
