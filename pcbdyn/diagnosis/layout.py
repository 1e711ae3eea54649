"""Where candidate effects can go on a meshed plate: its shell cells and nodes, its straight
boundary sides and support lines, prime-suspect points and part footprints.

A :class:`Layout` is made from any ``fe.Model`` (:func:`from_model`) or from a structure's built model
(:func:`from_structure`, which adds what the structure names as prime suspects and footprints: on a
board, the measurement points, declared masses and part footprints; on a box, its declared masses, its
plates as footprints and each plate's nodes). Candidate generators (the catalogue's plugins) only ask it
geometric questions: grid nodes, boundary segments, cells inside a polygon, the cells a line crosses.

A plate in one plane z = const (a board) is described in x, y (``planar``); a structure in 3-D (a box)
in x, y, z (``points``): its grid is a 3-D one, its footprints are planar polygons in space; stiffeners
are placed on each of its plates seen in its own plane (:meth:`Layout.plate_view`), and the kinds that act
along sides or in-plane axes (edge stiffness, line masses, point inertias) have no candidates there.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from matplotlib.path import Path as PolyPath
from scipy.spatial import cKDTree

from ..fe.model import SHELL_TYPES
from ..fe.probe import Locator, ProbeError, model_probe

#: direction change [deg] above which a boundary node is a corner that ends a straight side
CORNER_DEG = 15.0
#: [element sizes] how far from the cells a line's point may lie and count as on the plate: the points
#: are in the plate's plane, so any distance means beyond the outline (the locator's default, a tenth
#: of a cell, took a rib end 0.02 mm past an edge as on it and made a piece of no length there: a beam
#: of unbounded stiffness that left the finer meshes indefinite)
ON_PLATE = 1e-6
#: [m] how far from the cells a point may lie and count as on them when placed between nodes (round-off)
OFF_EDGE = 1e-9


@dataclass
class Layout:
    """``sides``: {name: ordered node chain} of the straight boundary sides and the support lines of
    edge springs (card guides); ``suspects``: {name: node}; ``footprints``: {name: polygon (m, 2) [m]}
    (planar polygons (m, 3) in 3-D); ``thickness``: plate thickness [m] (for stiffener offsets);
    ``plates``: {plate name: its nodes} of a structure made of several plates (empty on a board)."""

    model: object
    shell_sets: tuple
    sides: dict
    suspects: dict = field(default_factory=dict)
    footprints: dict = field(default_factory=dict)
    thickness: float = 0.0
    plates: dict = field(default_factory=dict)

    @property
    def xy(self) -> np.ndarray:
        return self.model.nodes[:, :2]

    @property
    def planar(self) -> bool:
        """True for shells in one plane z = const (a board)."""
        z = self.model.nodes[self.shell_nodes(), 2]
        return float(np.ptp(z)) <= 1e-9 * max(float(np.ptp(self.xy, axis=0).max()), 1e-300)

    @property
    def points(self) -> np.ndarray:
        """The node coordinates candidates are placed by: x, y on a plane, x, y, z in 3-D."""
        return self.xy if self.planar else self.model.nodes

    def plate_view(self, name: str) -> tuple:
        """(plate ``name`` as a layout in its own plane, its :class:`.plate_view.Frame`), made once."""
        from .plate_view import plate_view

        views = self.__dict__.setdefault("_plate_views", {})
        if name not in views:
            views[name] = plate_view(self, name)
        return views[name]

    def plate_of(self, node: int) -> str | None:
        """The (first) plate that holds ``node`` (None on a single plate)."""
        return next((name for name, nodes in self.plates.items() if np.isin(node, nodes)), None)

    def normal(self, node: int) -> np.ndarray:
        """The unit normal of the shells at ``node`` (the mean of its cells' normals, their sense made
        to agree with the first)."""
        normals = []
        for _, conn in self.cells():
            for c in conn[np.any(conn == node, axis=1)]:
                p = self.model.nodes[c]
                normals.append(np.cross(p[2] - p[0], p[-1] - p[1] if len(c) == 4 else p[1] - p[0]))
        n = np.array(normals)
        n *= np.where(n @ n[0] < 0, -1.0, 1.0)[:, None]
        m = n.sum(axis=0)
        return m / np.linalg.norm(m)

    def cells(self):
        """[(set name, conn)] of the shell sets."""
        return [(n, self.model.sets[n].conn) for n in self.shell_sets]

    def shell_nodes(self) -> np.ndarray:
        return np.unique(np.concatenate([c.ravel() for _, c in self.cells()]))

    def onto_plate(self, xy) -> tuple | None:
        """The point of a planar plate's shell cells nearest to ``xy`` [m] (x, y): ``xy`` itself on the plate,
        its projection onto the outline where it lies past an edge within the locator's tolerance (a tenth
        of a cell), None beyond. A point walked that little past an edge is on this mesh but off the finer
        ones the mesh correction places it on, whose tolerance is finer (hold-out ``ho_transducer_cfg``: a
        spring walked to 0.33 mm past the edge of 6.75 mm cells stopped the finer meshes' solve)."""
        z = float(self.model.nodes[self.shell_nodes()[0], 2])
        try:
            loc = model_probe(self.model, [[xy[0], xy[1], z]]).location
        except ProbeError:
            return None
        if loc.distance[0] <= OFF_EDGE:
            return float(xy[0]), float(xy[1])
        x, y = loc.weights[0] @ self.xy[loc.nodes[0]]
        return float(x), float(y)

    def grid_nodes(self, spacing: float | None = None) -> np.ndarray:
        """Shell nodes nearest to a square grid of pitch ``spacing`` [m] (None: every shell node)."""
        nodes = self.shell_nodes()
        if spacing is None:
            return nodes
        if not spacing > 0:
            raise ValueError(f"spacing must be > 0 m or None (every node), got {spacing}")
        if not self.planar:  # one node per occupied cube of the 3-D grid: the one nearest the cube's nodes' mean
            xyz = self.model.nodes[nodes]
            _, cube = np.unique(np.floor((xyz - xyz.min(axis=0)) / spacing).astype(np.int64), axis=0,
                                return_inverse=True)
            cube = cube.ravel()
            centre = np.array([np.bincount(cube, xyz[:, k]) for k in range(3)]).T / np.bincount(cube)[:, None]
            d = np.linalg.norm(xyz - centre[cube], axis=1)
            order = np.lexsort((d, cube))
            return np.unique(nodes[order[np.r_[True, np.diff(cube[order]) != 0]]])
        xy = self.xy[nodes]
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        gx = np.arange(lo[0] + 0.5 * spacing, hi[0], spacing)
        gy = np.arange(lo[1] + 0.5 * spacing, hi[1], spacing)
        g = np.stack(np.meshgrid(gx, gy), axis=-1).reshape(-1, 2)
        d, near = cKDTree(xy).query(g)
        return np.unique(nodes[near[d < 0.5 * spacing]])

    def segments(self, n: int) -> list:
        """[(side name, i, node chain)]: every side cut into ``n`` pieces of about equal length
        (fewer where the side has too few elements)."""
        if int(n) != n or n < 1:
            raise ValueError(f"segments must be an integer >= 1, got {n}")
        out = []
        for name, chain in self.sides.items():
            p = self.xy[chain]
            s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
            cuts = np.unique(np.abs(s[:, None] - np.linspace(0.0, s[-1], int(n) + 1)).argmin(axis=0))
            for i, (a, b) in enumerate(zip(cuts[:-1], cuts[1:])):
                out.append((name, i, chain[a:b + 1]))
        return out

    def segment_runs(self, n: int) -> list:
        """[(side name, (i, j), node chain)]: every run of consecutive pieces i to j of :meth:`segments`
        (i = j: one piece; the whole side included), so that an effect over part of a side is one
        candidate wherever it starts and ends on the n cuts."""
        pieces: dict = {}
        for name, i, chain in self.segments(n):
            pieces.setdefault(name, []).append(chain)
        out = []
        for name, chains in pieces.items():
            for i in range(len(chains)):
                for j in range(i, len(chains)):
                    run = np.concatenate([chains[i]] + [c[1:] for c in chains[i + 1:j + 1]])
                    out.append((name, (i, j), run))
        return out

    def nearest_node(self, xy) -> int:
        """The shell node nearest to the point ``xy`` [m] (x, y, z in 3-D)."""
        nodes = self.shell_nodes()
        return int(nodes[np.linalg.norm(self.points[nodes] - np.asarray(xy, float), axis=1).argmin()])

    def side_chain(self, segment, tol: float = 0.01) -> np.ndarray:
        """The node chain of the side (or support line) that runs nearest to both ends of
        ``segment`` [[x, y], [x, y]] [m], from the node nearest one end to the node nearest the
        other; ValueError when no side passes within ``tol`` [m] of the ends."""
        a, b = (np.asarray(p, float) for p in segment)
        best = None
        for chain in self.sides.values():
            p = self.xy[chain]
            da, db = np.linalg.norm(p - a, axis=1), np.linalg.norm(p - b, axis=1)
            if best is None or da.min() + db.min() < best[0]:
                i, j = sorted((int(da.argmin()), int(db.argmin())))
                best = (da.min() + db.min(), chain[i:j + 1])
        if best is None or best[0] > tol or best[1].size < 2:
            raise ValueError(f"the segment {np.round(1e3 * np.array([a, b]), 2).tolist()} mm does not run along a "
                             "side or support line of the plate")
        return best[1]

    def cells_in(self, polygon) -> list:
        """[(set name, cell indices)] of the shell cells whose centroid lies in ``polygon`` [m] (a planar
        polygon (m, 3) in 3-D: centroids in its plane, within a thousandth of its size, and inside)."""
        polygon = np.asarray(polygon, dtype=float)
        if polygon.shape[1] == 3:
            return self._cells_in_3d(polygon)
        path = PolyPath(polygon)
        out = []
        for name, conn in self.cells():
            inside = np.flatnonzero(path.contains_points(self.xy[conn].mean(axis=1)))
            if inside.size:
                out.append((name, inside))
        return out

    def _cells_in_3d(self, polygon) -> list:
        o = polygon[0]
        e1 = polygon[1] - o
        e1 /= np.linalg.norm(e1)
        n = np.cross(e1, polygon[-1] - o)
        n /= np.linalg.norm(n)
        frame = np.array([e1, np.cross(n, e1)])
        path = PolyPath((polygon - o) @ frame.T)
        tol = 1e-3 * float(np.ptp(polygon, axis=0).max())
        out = []
        for name, conn in self.cells():
            c = self.model.nodes[conn].mean(axis=1) - o
            inside = np.flatnonzero((np.abs(c @ n) < tol) & path.contains_points(c @ frame.T, radius=1e-9))
            if inside.size:
                out.append((name, inside))
        return out

    @property
    def element_size(self) -> float:
        """Median length [m] of the shell cells' edges."""
        e = _edges([c for _, c in self.cells()])
        return float(np.median(np.linalg.norm(self.points[e[:, 0]] - self.points[e[:, 1]], axis=1)))

    @cached_property
    def _mesh_lines(self) -> _MeshLines:
        xy = self.xy
        e = _edges([c for _, c in self.cells()])
        nodes = self.shell_nodes()
        size = self.element_size
        return _MeshLines(xy[e[:, 0]], xy[e[:, 1]] - xy[e[:, 0]], xy[nodes], 1e-6 * size,
                          float(np.mean(self.model.nodes[nodes, 2])),
                          Locator(self.model.nodes, [(self.model.sets[nm].etype, c) for nm, c in self.cells()],
                                  tol=ON_PLATE * size))

    def line_cells(self, p0, p1):
        """The straight line from ``p0`` to ``p1`` cut where it crosses the shell cells' edges or
        passes a node (each piece within one cell), the pieces' ends located in the cells: (host
        nodes (n, 8), the ends' shape-function weights (n, 2, 8), end points (n, 2, 2) [m]), as
        :mod:`..fe.elements.embedded_beam` takes them. Along a row of nodes the pieces end on the
        nodes (a beam on that row). Pieces off the plate (beyond :data:`ON_PLATE`) are left out."""
        m = self._mesh_lines
        p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
        d = p1 - p0
        L2 = float(d @ d)
        a, u = m.start, m.step
        den = d[0] * u[:, 1] - d[1] * u[:, 0]
        w = a - p0
        ok = np.abs(den) > 1e-12 * np.sqrt(L2) * np.linalg.norm(u, axis=1)
        den = np.where(ok, den, 1.0)
        t = (w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0]) / den
        sgm = (w[:, 0] * d[1] - w[:, 1] * d[0]) / den
        crossing = t[ok & (sgm >= 0) & (sgm <= 1)]
        r = m.nodes - p0
        on_line = np.abs(r[:, 0] * d[1] - r[:, 1] * d[0]) / np.sqrt(L2) < m.on_line
        ts = np.sort(np.r_[0.0, 1.0, crossing, (r[on_line] @ d) / L2])
        ts = ts[(ts >= 0) & (ts <= 1)]
        ts = ts[np.r_[True, np.diff(ts) > 1e-9]]
        pts = p0 + ts[:, None] * d
        mids = 0.5 * (pts[:-1] + pts[1:])
        both = m.locate(np.column_stack([np.vstack([pts, mids]), np.full(len(pts) + len(mids), m.z)]))
        n = len(pts)
        keep = both.found[:n - 1] & both.found[1:n] & both.found[n:]
        conn = np.hstack([both.nodes[:n - 1], both.nodes[1:n]])[keep]
        W = np.zeros((len(mids), 2, 8))
        W[:, 0, :4], W[:, 1, 4:] = both.weights[:n - 1], both.weights[1:n]
        return conn, W[keep], np.stack([pts[:-1], pts[1:]], axis=1)[keep]


@dataclass(frozen=True)
class _MeshLines:
    """What :meth:`Layout.line_cells` asks of the mesh for every line: the cells' edges (start, step
    (n, 2) [m]), the shell nodes' x, y, the distance [m] within which a node lies on a line, the
    plane's z and the cells' :class:`..fe.probe.Locator`."""

    start: np.ndarray
    step: np.ndarray
    nodes: np.ndarray
    on_line: float
    z: float
    locate: object


def _edges(conns) -> np.ndarray:
    """All element edges (with repeats) as sorted node pairs."""
    e = [np.stack([c, np.roll(c, -1, axis=1)], axis=-1).reshape(-1, 2) for c in conns]
    return np.sort(np.concatenate(e), axis=1)


def _chains(edges) -> list:
    """Ordered node chains (open paths first from an end; closed loops repeat their first node)."""
    adj: dict = {}
    for a, b in edges:
        adj.setdefault(int(a), []).append(int(b))
        adj.setdefault(int(b), []).append(int(a))
    seen, out = set(), []
    starts = [n for n, nb in adj.items() if len(nb) == 1] + list(adj)
    for s in starts:
        if s in seen:
            continue
        chain, prev = [s], None
        seen.add(s)
        while True:
            nxt = [m for m in adj[chain[-1]] if m != prev and (m not in seen or (m == s and len(chain) > 2))]
            if not nxt:
                break
            prev = chain[-1]
            chain.append(nxt[0])
            if nxt[0] == s:
                break
            seen.add(nxt[0])
        out.append(np.array(chain, dtype=np.int64))
    return out


def _straight_sides(chain: np.ndarray, xy: np.ndarray) -> list:
    """A boundary chain cut at its corners into straight sides."""
    closed = chain.size > 2 and chain[0] == chain[-1]
    p = xy[chain]
    d = np.diff(p, axis=0)
    d /= np.linalg.norm(d, axis=1)[:, None]
    if closed:
        turn = np.r_[np.einsum("ij,ij->i", d[-1:], d[:1]), np.einsum("ij,ij->i", d[:-1], d[1:])]
        corner = np.flatnonzero(turn < np.cos(np.radians(CORNER_DEG)))  # index into chain[:-1]
        if corner.size == 0:
            return [chain]
        ring = chain[:-1]
        ring = np.r_[ring[corner[0]:], ring[:corner[0]]]
        cuts = np.r_[corner - corner[0], ring.size]
        ring = np.r_[ring, ring[0]]
        return [ring[a:b + 1] for a, b in zip(cuts[:-1], cuts[1:])]
    turn = np.einsum("ij,ij->i", d[:-1], d[1:])
    cuts = np.r_[0, 1 + np.flatnonzero(turn < np.cos(np.radians(CORNER_DEG))), chain.size - 1]
    return [chain[a:b + 1] for a, b in zip(cuts[:-1], cuts[1:])]


def _side_name(xy: np.ndarray, i: int) -> str:
    for axis, label in ((0, "x"), (1, "y")):
        if np.ptp(xy[:, axis]) < 1e-9:
            return f"{label}={1e3 * xy[0, axis]:g}mm"
    return f"side{i}"


def _thickness(prop) -> float:
    """Plate thickness from a shell property: t = sqrt(12 D11 / A11) (exact for a homogeneous plate)."""
    return float(np.sqrt(12.0 * prop.bending()[0, 0] / prop.membrane()[0, 0]))


def from_model(model, suspects=None, footprints=None, thickness: float | None = None, plates=None) -> Layout:
    """The layout of the shell sets of any fe.Model; boundary sides from the cell edges used once,
    support lines from its edge-spring sets."""
    shells = tuple(n for n, s in model.sets.items() if s.etype in SHELL_TYPES and len(s.conn))
    if not shells:
        raise ValueError("the model has no shell elements: candidate effects are placed on a plate")
    e, count = np.unique(_edges([model.sets[n].conn for n in shells]), axis=0, return_counts=True)
    z = model.nodes[np.unique(e), 2]
    xy = model.nodes[:, :2] if np.ptp(z) <= 1e-9 * max(float(np.ptp(model.nodes[:, :2], axis=0).max()), 1e-300) \
        else model.nodes
    chains = [s for c in _chains(e[count == 1]) for s in _straight_sides(c, xy)]
    chains += [c for n, s in model.sets.items() if s.etype == "edge_spring" for c in _chains(np.sort(s.conn, axis=1))]
    sides: dict = {}
    known: list = []
    for i, c in enumerate(chains):
        key = frozenset(c.tolist())
        if key in known:
            continue
        known.append(key)
        name = _side_name(xy[c], i)
        sides[name if name not in sides else f"{name}#{i}"] = c
    t = thickness if thickness is not None else _thickness(model.sets[shells[0]].prop)
    return Layout(model, shells, sides, dict(suspects or {}), dict(footprints or {}), t, dict(plates or {}))


def from_structure(pm) -> Layout:
    """The layout of a structure's built model ``pm`` (e.g. :class:`pcbdyn.board.BoardModel`), with the
    prime suspects, footprints and plate thickness of its ``layout_hints()`` (on a board: measurement
    points and declared masses, part footprints) and, for a structure of several plates, the nodes of
    each (``plate_nodes()``)."""
    suspects, footprints, thickness = pm.layout_hints()
    plates = pm.plate_nodes() if hasattr(pm, "plate_nodes") else None
    return from_model(pm.model, suspects, footprints, thickness, plates)
