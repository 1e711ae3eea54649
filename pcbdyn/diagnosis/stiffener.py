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
from .catalogue import register, Blocks, Candidate


class _Stiffener:
    name = report_as = "stiffener"
    param = "EI"
    unit = "N*m^2"
    scale = 1.0
    lower = 0.0
    options = ("path_spacing",)
    reanalysed = False  # a rib changes the modes beyond a first-order basis (:mod:`.scan`)
    # a stiff bar pins the plate along its line: its linear score under-rates it where it reshapes the
    # modes (a steel bar across a clamped card: the line through it 73rd of 504 by that score, 2nd of its
    # 100 best on the reanalysis, which ranks though it does not fit ribs: :func:`.scan.saturated`)
    saturates = True
    saturated_values = (0.03, 0.1, 0.3, 1.0)
    saturated_screen = 100

    def __init__(self, section: RibSection = RibSection()):
        self.section = section

    def generate(self, layout, path_spacing: float = 0.02) -> list:
        """Lines across the whole plate in :data:`DIRECTIONS`, ``path_spacing`` [m] apart, and their
        :data:`PIECES`: a bar at any angle and of any length starts from the line it lies nearest (its ends,
        direction and section are fitted after, :mod:`.geometry_fit`). On a structure in 3-D, on each of
        its plates in the plate's own plane (:meth:`.layout.Layout.plate_view`), standing on its inside."""
        if not path_spacing > 0:
            raise ValueError(f"path_spacing must be > 0 m, got {path_spacing}")
        plates = [None] if layout.planar else list(layout.plates)
        out = []
        for plate in plates:
            for p0, p1 in _lines(in_its_plane(layout, plate)[0], path_spacing):
                c = self.candidate(layout, None, p0, p1, plate=plate)
                if c is not None:
                    out.append(c)
        return out

    def parallel(self, layout, candidate, offsets) -> list:
        """``candidate``'s line moved across itself by ``offsets`` [m] (same length and direction;
        the pieces off the plate left out)."""
        path, plate = in_plane(candidate), candidate.data.get("plate")
        out = []
        for o in np.asarray(offsets, float):
            c = self.candidate(layout, None, *(path + o * normal(path)), height=candidate.data.get("height"),
                               plate=plate)
            if c is not None:
                out.append(c)
        return out

    def along(self, candidate, path):
        """``candidate`` on the straight line ``path`` (2, 2) [m] of its plate's plane instead (a board's
        x, y: :func:`in_plane`), named for it (a rib moved to where another mesh, on which it is placed
        (:meth:`place`), follows it)."""
        flat = np.asarray(path, float)[[0, -1]]
        tag, data = self._tag(flat, candidate.data.get("height")), candidate.data
        if "frame" in data:
            tag, data = f"{data['plate']}:{tag}", {**data, "plane_path": flat}
        path = lifted(candidate, flat)
        return replace(candidate, name=f"{self.name}@{tag}", at=tuple(path.mean(axis=0)),
                       geometry={**candidate.geometry, "path": path}, data=data)

    def _tag(self, path, height) -> str:
        """The name of a rib from its ends and, where it is not the kind's, its section height."""
        same = height is None or np.isclose(height, self.section.h, rtol=1e-9, atol=0.0)
        return label(path) + ("" if same else f"/h={1e3 * height:.4g}mm")

    def candidate(self, layout, name, p0, p1, height: float | None = None, plate: str | None = None):
        """The rib along the straight line ``p0``-``p1`` [m] called ``stiffener@<name>`` (None: named
        for its ends on the plate), of section ``height`` [m] (None: the kind's; the mass per length
        of a rib of stiffness EI is 12 rho EI / (E h^2)); None where the line misses the plate. On a
        structure in 3-D, ``p0`` and ``p1`` are in the plane of its ``plate`` (:mod:`.plate_view`): the
        candidate's path is in space, its ``plane_path`` in the plate's plane."""
        view, frame = in_its_plane(layout, plate)
        conn, weights, ends = view.line_cells(p0, p1)
        if not len(conn):
            return None
        flat = np.vstack([ends[:1, 0], ends[-1:, 1]])
        length = float(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).sum())
        h = self.section.h if height is None else float(height)
        data = {"conn": conn, "weights": weights, "length": length, "thickness": view.thickness, "height": h}
        path, tag = flat, name or self._tag(flat, height)
        if frame is not None:
            path, tag = frame.lift(flat), f"{plate}:{tag}"
            data.update(plate=plate, plane_path=flat, normal=frame.normal, frame=frame)
        return Candidate(self.name, f"{self.name}@{tag}", tuple(path.mean(axis=0)), np.unique(conn), {"path": path}, data)

    def place(self, layout, candidate):
        """Along ``candidate``'s line, of its section (ValueError where it misses the plate)."""
        c = self.candidate(layout, "placed", *in_plane(candidate), height=candidate.data.get("height"),
                           plate=candidate.data.get("plate"))
        if c is None:
            raise ValueError(f"{candidate.name}: its line misses the plate")
        return c

    def whole(self, candidates, i: int) -> int:
        """The index of the longest stiffener of ``candidates`` on candidate ``i``'s line (a bar across the
        card was found as a middle piece whose ends, fitted after, stopped 33 mm short of either edge)."""
        plate = candidates[i].data.get("plate")
        ribs = [j for j, c in enumerate(candidates) if c.kind == self.name and c.data.get("plate") == plate]
        paths = [in_plane(candidates[j]) for j in ribs]
        n = np.array([normal(q) for q in paths])
        offset = np.einsum("ij,ij->i", n, np.array([q[0] for q in paths]))
        length = np.array([np.linalg.norm(q[1] - q[0]) for q in paths])
        k = ribs.index(i)
        same = np.flatnonzero((np.abs(n - n[k]).max(axis=1) < 1e-9) & (np.abs(offset - offset[k]) < 1e-9))
        return ribs[same[np.argmax(length[same])]]

    def section_of(self, candidate) -> RibSection:
        """The rib's section: the kind's material at the candidate's height."""
        return replace(self.section, h=candidate.data.get("height", self.section.h))

    def mass(self, candidate, value: float) -> float:
        """[kg] the rib's mass at stiffness ``value`` (EI): rho b h times its length, b = 12 EI / (E h^3)."""
        sec = self.section_of(candidate)
        return 12.0 * sec.rho * value / (sec.E * sec.h**2) * candidate.data["length"]

    def _property(self, value: float, candidate):
        return EmbeddedBeamProperty(rib_property(value, candidate.data["thickness"], self.section_of(candidate),
                                                 candidate.data.get("normal", (0.0, 0.0, 1.0))),
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
        m = model.copy()
        m.add(f"effects.{candidate.name}", "embedded_beam2", candidate.data["conn"], self._property(value, candidate))
        return m


#: [rad] the directions of the lines searched first: rows, columns and the diagonals between them
DIRECTIONS = np.radians([0.0, 90.0, 45.0, 135.0])
#: the stretches of each line searched first (fractions of its length across the plate): the whole, and
#: halves at either end and in the middle (a bar glued over part of the board is nearer one of them)
PIECES = ((0.0, 1.0), (0.0, 0.5), (0.5, 1.0), (0.25, 0.75))


def in_plane(candidate) -> np.ndarray:
    """The ends (2, 2) [m] of a stiffener candidate's line in its plate's plane (a board's x, y)."""
    return np.asarray(candidate.data.get("plane_path", candidate.geometry["path"]), float)[[0, -1]]


def in_its_plane(layout, plate: str | None) -> tuple:
    """(the layout of ``plate`` seen in its plane, its :class:`.plate_view.Frame`); a board's own layout
    and None where ``plate`` is None."""
    return (layout, None) if plate is None else layout.plate_view(plate)


def lifted(candidate, flat) -> np.ndarray:
    """Points ``flat`` (..., 2) [m] of the plane of ``candidate``'s plate in space (on a board, as they are)."""
    frame = candidate.data.get("frame")
    return np.asarray(flat, float) if frame is None else frame.lift(flat)


def _lines(layout, path_spacing: float):
    """The ends (p0, p1) of the lines :meth:`_Stiffener.generate` tries on a plate in its plane."""
    lo, hi = extent(layout)
    centre = 0.5 * (lo + hi)
    for angle in DIRECTIONS:
        d = np.array([np.cos(angle), np.sin(angle)])
        d[np.abs(d) < 1e-12] = 0.0
        across = np.array([-d[1], d[0]])
        half = 0.5 * float(np.abs(hi - lo) @ np.abs(across))  # the plate's half-width across the lines
        n = max(1, int(round(2.0 * half / path_spacing)))
        for s in -half + (np.arange(n) + 0.5) * (2.0 * half / n):
            ends = _clipped(centre + s * across, d, lo, hi)
            for a, b in [] if ends is None else PIECES:
                yield ends[0] + a * (ends[1] - ends[0]), ends[0] + b * (ends[1] - ends[0])


def normal(path) -> np.ndarray:
    """The unit normal (2,) of the straight line ``path``, its larger component positive (+x across a
    column, +y across a row, whichever way the path runs)."""
    (x0, y0), (x1, y1) = np.asarray(path, float)[[0, -1]]
    n = np.array([y0 - y1, x1 - x0]) / np.hypot(x1 - x0, y1 - y0)
    return -n if n[np.argmax(np.abs(n))] < 0 else n


def label(path) -> str:
    """The name of the line ``path`` from its ends: ``(x0,y0)-(x1,y1)mm``."""
    (x0, y0), (x1, y1) = 1e3 * np.asarray(path, float)[[0, -1]]
    return f"({x0:.4g},{y0:.4g})-({x1:.4g},{y1:.4g})mm"


def _clipped(point, d, lo, hi):
    """The ends (2, 2) of the line through ``point`` along ``d`` inside the box ``lo``-``hi`` (None
    where it misses the box)."""
    t0, t1 = -np.inf, np.inf
    for k in range(2):
        if d[k] == 0.0:
            if not lo[k] <= point[k] <= hi[k]:
                return None
            continue
        a, b = sorted(((lo[k] - point[k]) / d[k], (hi[k] - point[k]) / d[k]))
        t0, t1 = max(t0, a), min(t1, b)
    return None if t1 <= t0 else np.array([point + t0 * d, point + t1 * d])


def extent(layout):
    """(lowest, highest) (2,) [m] corners of the box around ``layout``'s shell nodes in its plane."""
    xy = layout.xy[layout.shell_nodes()]
    return xy.min(axis=0), xy.max(axis=0)


KIND = _Stiffener()
register(KIND)
