"""One conforming quad-dominant shell mesh of all the plates of a box, in 3-D, with gmsh (OpenCASCADE).

Every plate is a plane surface; the surfaces are fragmented together with the rib lines and the points
that must be nodes (point masses), so that edges two plates share are one curve meshed once (the plates
share its nodes), and every rib line is a chain of element edges in its plate. Triangles are recombined
into quads as on boards (:mod:`pcbdyn.board.mesh`: frontal-Delaunay + blossom, and where triangles
remain, the mesh at twice the size split into quads).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..board.mesh import mesh_nodes, quad_pass, run_quad_mesh, surface_cells, tagged_nodes, used_nodes
from ..fe.model import SHELL_TYPES


@dataclass
class BoxMesh:
    """Nodes (n, 3) [m]; cells per plate: {plate: {"quad4": (k, 4), "tri3": (k, 3)}}, ordered
    counter-clockwise about the plate's normal; ``point_nodes[i]``: the node at the i-th point asked for."""

    nodes: np.ndarray
    cells: dict = field(default_factory=dict)
    point_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def all_cells(self, etype: str) -> np.ndarray:
        arrs = [c[etype] for c in self.cells.values() if etype in c and len(c[etype])]
        return np.concatenate(arrs) if arrs else np.zeros((0, 4 if etype == "quad4" else 3), dtype=np.int64)

    def shells(self, plate: str | None = None) -> list:
        """[(etype, conn)] of one plate's cells (all plates' when None)."""
        if plate is not None:
            return [(k, c) for k, c in self.cells[plate].items() if len(c)]
        return [(k, self.all_cells(k)) for k in SHELL_TYPES if len(self.all_cells(k))]

    def plate_nodes(self, plate: str) -> np.ndarray:
        return np.unique(np.concatenate([c.ravel() for _, c in self.shells(plate)]))

    def chain(self, p0, p1, nodes=None, tol: float = 1e-7) -> np.ndarray:
        """The nodes (of ``nodes``, default all) on the segment p0-p1 [m], ordered from p0; each
        consecutive pair must be an element edge (the segment was embedded in the mesh)."""
        p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
        d = p1 - p0
        L = float(np.linalg.norm(d))
        cand = np.arange(len(self.nodes)) if nodes is None else np.asarray(nodes)
        rel = self.nodes[cand] - p0
        s = rel @ d / L
        off = np.linalg.norm(rel - np.outer(s / L, d), axis=1)
        on = cand[(off < tol) & (s > -tol) & (s < L + tol)]
        chain = on[np.argsort((self.nodes[on] - p0) @ d)]
        ends = (self.nodes[chain[[0, -1]]] - p0) @ d / L if chain.size >= 2 else None
        where = f"segment {np.round(p0 * 1e3, 3).tolist()} -> {np.round(p1 * 1e3, 3).tolist()} mm"
        if ends is None or abs(ends[0]) > tol or abs(ends[1] - L) > tol:
            raise RuntimeError(f"{where} is not a line of mesh nodes")
        known = set()
        for _, conn in self.shells():
            e = np.sort(np.stack([conn, np.roll(conn, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
            known.update(map(tuple, e.tolist()))
        if any((min(a, b), max(a, b)) not in known for a, b in zip(chain[:-1], chain[1:])):
            raise RuntimeError(f"{where} does not follow element edges")
        return chain


def _surface(occ, corners) -> int:
    pts = [occ.addPoint(*map(float, c)) for c in corners]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    return occ.addPlaneSurface([occ.addCurveLoop(lines)])


def mesh_box(plates, lines, points, size: float) -> BoxMesh:
    """Mesh ``plates`` (:class:`.entries.Plate`) at element size ``size`` [m] with the straight ``lines``
    [(p0, p1)] [m] (ribs) as element edges and ``points`` (k, 3) [m] as nodes."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    xyz, cells, point_nodes = run_quad_mesh(_box_cells, (plates, lines, points, size), "the box")
    return _compact(xyz, cells, point_nodes, points)


def _box_cells(plates, lines, points, size, plan) -> tuple:
    """The box meshed by gmsh in one pass of ``plan`` (:func:`.board.mesh.run_quad_mesh`): (the surfaces
    that folded, (node xyz, cells {plate: {etype: [conn, ...]}}, node row of each point) or None where
    some folded)."""

    def build(gmsh):
        """The plates fragmented by the ribs' lines and the points: (each plate's surfaces, the point
        entities)."""
        occ = gmsh.model.occ
        objects = [(2, _surface(occ, p.corners())) for p in plates]
        tools = [(1, occ.addLine(occ.addPoint(*map(float, a)), occ.addPoint(*map(float, b)))) for a, b in lines]
        tools += [(0, occ.addPoint(*map(float, p))) for p in points]
        if tools or len(objects) > 1:
            _, out_map = occ.fragment(objects, tools)
        else:  # one plate alone: nothing to fragment
            out_map = [objects]
        occ.synchronize()
        surfaces = [[t for d, t in m if d == 2] for m in out_map[:len(plates)]]
        return surfaces, out_map[len(out_map) - len(points):] if len(points) else []

    with quad_pass("box", build, size, plan) as (gmsh, (surfaces, point_tags), folded):
        if folded:
            return folded, None
        xyz, index = mesh_nodes(gmsh)
        cells: dict = {}
        for plate, tags_p in zip(plates, surfaces):
            for t in tags_p:
                for conn in surface_cells(gmsh, t, index):
                    key = "quad4" if conn.shape[1] == 4 else "tri3"
                    cells.setdefault(plate.name, {}).setdefault(key, []).append(_oriented(xyz, conn, plate))
        return folded, (xyz, cells, tagged_nodes(gmsh, point_tags, index))


def _oriented(xyz, conn, plate) -> np.ndarray:
    """The cells of one surface (none folded: :func:`.board.mesh.folded_surfaces`) ordered
    counter-clockwise about the plate's normal."""
    p = xyz[conn]
    area = np.einsum("ck,k->c", sum(np.cross(p[:, i], p[:, (i + 1) % p.shape[1]]) for i in range(p.shape[1])),
                     plate.normal)
    conn = conn.copy()
    conn[area < 0] = conn[area < 0][:, ::-1]
    return conn


def _compact(xyz, cells, point_nodes, points) -> BoxMesh:
    """The mesh on the nodes that cells use (gmsh keeps construction points), renumbered."""
    nodes, new = used_nodes(xyz, cells)
    pn = np.array([new[p] if p >= 0 else -1 for p in point_nodes], dtype=np.int64)
    for i in np.flatnonzero(pn < 0):  # a point gmsh merged into an existing vertex: the coincident node
        d = np.linalg.norm(nodes - points[i], axis=1)
        if d.min() > 1e-7:
            raise RuntimeError(f"point {np.round(points[i] * 1e3, 3).tolist()} mm did not become a mesh node")
        pn[i] = int(np.argmin(d))
    return BoxMesh(nodes, cells, pn)
