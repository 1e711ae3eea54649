"""Quad-dominant shell meshes of a board with gmsh (OpenCASCADE kernel, quiet, each pass in a child process
with a time limit: :func:`run_quad_mesh`, :func:`run_gmsh`).

The board face is fragmented by every region that must own its own elements (part footprints)
or whose outline element edges must follow (wedge-lock contact strips), and by the points that
must be nodes (standoffs, point masses, part centres, measurement points). Triangles are
recombined into quads (frontal-Delaunay triangles + blossom recombination), which gives an
all-quad mesh for most layouts (gmsh's "frontal-Delaunay for quads", algorithm 8, folded a few
elements at small standoff pads, so algorithm 6 is used); when some triangles remain, the board is
meshed at twice the size and every cell is split into quads (gmsh's all-quad subdivision), so the
result is all-quad at ``size``; where that folds an element, the first mesh stays, with its few
triangles. Where the first pass folds (in the slivers between close footprints, or where a line
passes a footprint's corner), the subdivided mesh is made, and where that folds too, the same with
the folded surfaces' triangles split into quads (:func:`run_quad_mesh`). Triangles left anywhere are
Mindlin plates as the quads are (:mod:`pcbdyn.fe.elements.shell_tri3`), so a mixed mesh keeps one
plate theory; the all-quad fallback is kept because it is the closer of the two: on the six-part card
with a line 0.1 mm from U6's corner, the first eight frequencies move by 0.13 % (model mesh) and
0.014 % (a quarter of it) from the card without the line, against 0.18 % and 0.034 % with the folded
surface left in triangles. Meshing subdivided also where a first pass that does not fold leaves a few
triangles changed the discretisation between the neighbouring lines a fit walks
(:mod:`pcbdyn.diagnosis.geometry_fit`) more than the lines do, so those stay (0.3 to 20 % of the
cells of 7 of the 24 generated boards of benchmarks/discovery's splits)."""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from ..fe.model import SHELL_TYPES

_LOCK = threading.Lock()  # gmsh is one global state per process (a child's, or this one's without fork)


@dataclass
class BoardMesh:
    """Nodes (n, 3) [m]; cells per region label: {label: {"quad4": (n, 4), "tri3": (n, 3)}};
    ``point_nodes[i]``: the node at the i-th requested point."""

    nodes: np.ndarray
    cells: dict = field(default_factory=dict)
    point_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def all_cells(self, etype):
        arrs = [c[etype] for c in self.cells.values() if etype in c and len(c[etype])]
        n = 4 if etype == "quad4" else 3
        return np.concatenate(arrs) if arrs else np.zeros((0, n), dtype=np.int64)

    def edges_on_line(self, axis: int, value: float, tol: float = 1e-7) -> np.ndarray:
        """Unique element edges (2-node cells) lying on the line x=value (axis 0) or y=value (axis 1)."""
        on = np.abs(self.nodes[:, axis] - value) < tol
        edges = []
        for etype in SHELL_TYPES:
            conn = self.all_cells(etype)
            if not len(conn):
                continue
            e = np.stack([conn, np.roll(conn, -1, axis=1)], axis=-1).reshape(-1, 2)
            edges.append(e[on[e[:, 0]] & on[e[:, 1]]])
        e = np.sort(np.concatenate(edges), axis=1) if edges else np.zeros((0, 2), dtype=np.int64)
        return np.unique(e, axis=0)


    def chain_on_segment(self, p0, p1, tol: float = 1e-7) -> np.ndarray:
        """The nodes lying on the straight segment p0 -> p1, ordered from p0; consecutive nodes are
        checked to be element edges (the segment was embedded in the mesh)."""
        p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
        d = p1 - p0
        L = float(np.linalg.norm(d))
        rel = self.nodes[:, :2] - p0
        s = rel @ d / L
        off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / L
        on = np.flatnonzero((off < tol) & (s > -tol) & (s < L + tol))
        chain = on[np.argsort(s[on])]
        if chain.size < 2 or abs(s[chain[0]]) > tol or abs(s[chain[-1]] - L) > tol:
            raise RuntimeError(f"segment {p0.tolist()} -> {p1.tolist()} m is not a line of mesh nodes")
        known = set()
        for etype in SHELL_TYPES:
            conn = self.all_cells(etype)
            if len(conn):
                e = np.sort(np.stack([conn, np.roll(conn, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
                known.update(map(tuple, e.tolist()))
        for a, b in zip(chain[:-1], chain[1:]):
            if (min(a, b), max(a, b)) not in known:
                raise RuntimeError(f"segment {p0.tolist()} -> {p1.tolist()} m does not follow element edges")
        return chain


#: [s] the longest gmsh may take to mesh one structure; the PCBDYN_MESH_TIMEOUT variable changes it
MESH_TIMEOUT = 600.0


def run_gmsh(fn, args):
    """``fn(*args)`` (a function that meshes in a :func:`gmsh_session` and returns plain arrays) run in a
    child process (:func:`pcbdyn.children.run_forked`) so that a mesh that does not finish within
    :data:`MESH_TIMEOUT` (or PCBDYN_MESH_TIMEOUT) seconds ends with a message instead of a hang, and a
    crash in gmsh cannot take pcbdyn down. gmsh's own errors come back as RuntimeError."""
    import os

    from ..children import run_forked

    timeout = float(os.environ.get("PCBDYN_MESH_TIMEOUT", MESH_TIMEOUT))
    try:
        return run_forked(fn, args, timeout, "gmsh", preload=["pcbdyn.board.mesh", "pcbdyn.box.mesh"])
    except TimeoutError as exc:
        raise RuntimeError(f"{exc}; use a larger mesh size or simpler geometry, or raise PCBDYN_MESH_TIMEOUT "
                           f"(now {timeout:g} s)") from None
    except RuntimeError:
        raise
    except Exception as exc:  # gmsh raises bare Exceptions (e.g. for points it cannot join into a line)
        if type(exc) is not Exception:
            raise
        raise RuntimeError(f"gmsh: {exc}") from None


@contextmanager
def gmsh_session(name: str):
    """gmsh, initialised quietly for one model called ``name`` and finalised after, one session at a time
    in this process (gmsh is one global state)."""
    import gmsh

    with _LOCK:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.option.setNumber("General.Verbosity", 1)
            gmsh.model.add(name)
            yield gmsh
        finally:
            gmsh.finalize()


#: the first pass of :func:`run_quad_mesh`: triangles recombined into quads at the size asked
QUADS = "quads"
#: its second pass: a mesh twice as coarse, every cell split into quads
SUBDIVIDED = "subdivided"


def run_quad_mesh(fn, args, what: str):
    """A quad mesh made by ``fn(*args, plan)`` (a function that meshes in :func:`quad_pass` and returns
    (the surfaces that folded, its plain arrays (xyz, cells, point nodes), or None where some folded)),
    one pass per child process (:func:`run_gmsh`). Quads come from frontal-Delaunay triangles
    recombined by blossom (:data:`QUADS`); where triangles remain, the mesh twice as coarse with every
    cell split into quads by the frontal-Delaunay for quads (:data:`SUBDIVIDED`; algorithm 6 on this
    pass gave other meshes run to run), and where that folds an element, the first mesh with its few
    triangles. Where the first folds, the subdivided mesh, and where that folds too, the same with the
    surfaces that folded left unrecombined, their triangles split into three quads each, which cannot
    fold. Each pass runs in a child of its own, forked from the same memory
    (:func:`pcbdyn.children.run_forked`): gmsh breaks ties between equal recombinations by where its
    objects lie in memory, and forked from a long run, or meshing again in one process after
    ``mesh.clear()``, it gave one board one of two meshes run to run (frequencies 1e-6 apart, and a
    diagnosis that turned on them)."""
    folded, out = run_gmsh(fn, (*args, QUADS))
    if not folded and not any("tri3" in c for c in out[1].values()):
        return out
    refolded, subdivided = run_gmsh(fn, (*args, SUBDIVIDED))
    if not refolded:
        return subdivided
    if not folded:
        return out
    refolded, split = run_gmsh(fn, (*args, frozenset(refolded)))
    if refolded:
        raise RuntimeError(f"gmsh folded elements of {what} where it recombined triangles into quads; "
                           "change mesh_size slightly")
    return split


@contextmanager
def quad_pass(name: str, build, size: float, plan):
    """A :func:`gmsh_session` holding the geometry ``build(gmsh)`` makes, meshed by one pass of
    :func:`run_quad_mesh`'s ``plan`` (:data:`QUADS`, :data:`SUBDIVIDED`, or the surfaces whose triangles
    are split without recombining them); yields (gmsh, what ``build`` returned, the surfaces that folded)."""
    with gmsh_session(name) as gmsh:
        built = build(gmsh)
        if plan == QUADS:
            _generate(gmsh, size, 6, recombine=True)
        elif plan == SUBDIVIDED:
            _generate(gmsh, 2.0 * size, 8, recombine=True, subdivide=True)
        else:
            _generate(gmsh, 2.0 * size, 8, recombine=[t for _, t in gmsh.model.getEntities(2) if t not in plan],
                      subdivide=True)
        yield gmsh, built, folded_surfaces(gmsh)


def _generate(gmsh, size: float, algorithm: int, recombine, subdivide: bool = False) -> None:
    """A 2-D mesh at ``size`` by gmsh's ``algorithm``, its triangles recombined into quads (blossom) on
    every surface (``recombine`` True) or on the surfaces listed, and every cell split into quads where
    ``subdivide``."""
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
    gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 1 if subdivide else 0)
    gmsh.option.setNumber("Mesh.Algorithm", algorithm)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.RecombineAll", 1 if recombine is True else 0)
    if recombine is not True:
        for t in recombine:
            gmsh.model.mesh.setRecombine(2, t)
    gmsh.model.mesh.generate(2)


def folded_surfaces(gmsh) -> set:
    """The surfaces whose elements do not all turn the same way about the surface's normal (a folded
    element); a surface in 3-D (a housing's plate) is judged in its own plane."""
    xyz, index = mesh_nodes(gmsh)
    out = set()
    for _, t in gmsh.model.getEntities(2):
        cells = surface_cells(gmsh, t, index)
        if not cells:
            continue
        normals = np.concatenate([_cell_normals(xyz, conn) for conn in cells])
        turn = normals @ normals.sum(axis=0)
        if turn.size and turn.min() < 0 < turn.max():
            out.add(t)
    return out


def _cell_normals(xyz, conn) -> np.ndarray:
    """Each cell's area vector (n, 3): half the sum of its edges' cross products (Newell)."""
    p = xyz[conn]
    return 0.5 * np.cross(p, np.roll(p, -1, axis=1)).sum(axis=1)


def mesh_nodes(gmsh) -> tuple:
    """(xyz (n, 3) of every node gmsh made, index: node tag -> row)."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(tags.size)
    return coords.reshape(-1, 3), index


def surface_cells(gmsh, tag: int, index) -> list:
    """The cells of surface ``tag`` as rows of node rows, one array per element type (triangles, quads)."""
    out = []
    types, _, enodes = gmsh.model.mesh.getElements(2, tag)
    for et, en in zip(types, enodes):
        npc = {2: 3, 3: 4}.get(int(et))
        if npc is None:
            raise RuntimeError(f"gmsh produced element type {et}; only triangles and quads are expected")
        out.append(index[np.asarray(en, dtype=np.int64).reshape(-1, npc)])
    return out


def tagged_nodes(gmsh, point_tags, index) -> list:
    """The node row of each point entity of ``point_tags`` (fragment results; -1 where gmsh merged it)."""
    out = []
    for pt in point_tags:
        ntags = gmsh.model.mesh.getNodes(0, pt[0][1])[0] if pt and pt[0][0] == 0 else []
        out.append(int(index[int(ntags[0])]) if len(ntags) else -1)
    return out


def _polygon(occ, v):
    pts = [occ.addPoint(float(x), float(y), 0.0) for x, y in v]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    return occ.addPlaneSurface([occ.addCurveLoop(lines)])


def _polyline(occ, v):
    pts = [occ.addPoint(float(x), float(y), 0.0) for x, y in v]
    return [occ.addLine(pts[i], pts[i + 1]) for i in range(len(pts) - 1)]


#: meshes kept by their inputs (least recently used dropped first): the configurations of one
#: board meshed alike (``shared_mesh``) are one mesh, made once per size
MESHES_KEPT = 8
_meshes: OrderedDict = OrderedDict()


def _mesh_key(outline, regions, points, size, strips, lines) -> bytes:
    h = hashlib.blake2b(digest_size=16)
    h.update(repr([len(outline.holes), [label for label, _ in regions], len(strips), len(lines)]).encode())
    for a in [outline.vertices, *outline.holes, *(p for _, p in regions), points, [size], *strips, *lines]:
        h.update(np.ascontiguousarray(np.asarray(a, dtype=float)).tobytes() + b"|")
    return h.digest()


def mesh_board(outline, regions, points, size: float, strips=(), lines=()) -> BoardMesh:
    """Mesh ``outline`` (vertices + holes) with element size ``size`` [m].

    ``regions``: [(label, polygon (m, 2))] whose elements get that label (first one wins where
    regions overlap); ``strips``: polygons whose outlines element edges follow but whose elements
    stay on the board; ``lines``: open polylines (m, 2) lying on the board that element edges
    follow (edge springs, line masses, stiffeners); ``points``: (k, 2) points that become nodes.
    Elements outside every region are labelled "board". The same inputs give a copy of the mesh
    made before (:data:`MESHES_KEPT`).
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    key = _mesh_key(outline, regions, points, size, strips, lines)
    if key not in _meshes:
        _meshes[key] = _mesh_board(outline, regions, points, size, strips, lines)
        while len(_meshes) > MESHES_KEPT:
            _meshes.popitem(last=False)
    _meshes.move_to_end(key)
    m = _meshes[key]
    return BoardMesh(m.nodes.copy(), {k: {e: c.copy() for e, c in v.items()} for k, v in m.cells.items()},
                     m.point_nodes.copy())


def _mesh_board(outline, regions, points, size: float, strips=(), lines=()) -> BoardMesh:
    """The mesh itself: gmsh in a child process under :func:`run_gmsh`'s time limit."""
    xyz, cells, point_nodes = run_quad_mesh(_board_cells, (outline.vertices, outline.holes, regions, points, size, strips,
                                                           lines), "the board")
    nodes, new = used_nodes(xyz, cells)
    for c in cells.values():
        for k in c:
            c[k] = _counter_clockwise(nodes, c[k])
    pn = np.array([new[p] if p >= 0 else -1 for p in point_nodes], dtype=np.int64)
    nodes[:, 2] = 0.0
    missing = np.flatnonzero(pn < 0)
    for i in missing:  # a point gmsh merged into an existing vertex: take the coincident node
        d = np.linalg.norm(nodes[:, :2] - points[i], axis=1)
        j = int(np.argmin(d))
        if d[j] > 1e-7:
            raise RuntimeError(f"point {points[i]} did not become a mesh node")
        pn[i] = j
    return BoardMesh(nodes, cells, pn)


def _board_cells(vertices, holes, regions, points, size, strips, lines, plan) -> tuple:
    """The board meshed by gmsh in one pass of ``plan`` (:func:`run_quad_mesh`): (the surfaces that folded,
    (node xyz, cells {label: {etype: [conn, ...]}}, node row of each point) or None where some folded)."""

    def build(gmsh):
        """The board's face fragmented by its regions, strips, lines and points: (the surfaces on the
        board, their region labels, the point entities)."""
        occ = gmsh.model.occ
        board = _polygon(occ, vertices)
        if holes:
            cut, _ = occ.cut([(2, board)], [(2, _polygon(occ, h)) for h in holes])
            board_tags = [t for d, t in cut if d == 2]
        else:
            board_tags = [board]
        tools = [(2, _polygon(occ, poly)) for _, poly in regions]
        tools += [(2, _polygon(occ, poly)) for poly in strips]
        tools += [(1, t) for line in lines for t in _polyline(occ, line)]
        tools += [(0, occ.addPoint(float(x), float(y), 0.0)) for x, y in points]
        objects = [(2, t) for t in board_tags]
        if tools:
            _, out_map = occ.fragment(objects, tools)
        else:
            out_map = [[o] for o in objects]
        occ.synchronize()
        nb = len(objects)
        on_board = {t for m in out_map[:nb] for d, t in m if d == 2}
        label_of = {}
        for i, (label, _) in enumerate(regions):
            for d, t in out_map[nb + i]:
                if d == 2 and t in on_board and t not in label_of:
                    label_of[t] = label
        extra = [(2, t) for m in out_map[nb:] for d, t in m if d == 2 and t not in on_board]
        if extra:
            gmsh.model.removeEntities(extra, recursive=True)
        point_tags = [out_map[-len(points) + i] for i in range(len(points))] if len(points) else []
        return on_board, label_of, point_tags

    with quad_pass("board", build, size, plan) as (gmsh, (on_board, label_of, point_tags), folded):
        if folded:
            return folded, None
        xyz, index = mesh_nodes(gmsh)
        cells: dict = {}
        for t in sorted(on_board):
            label = label_of.get(t, "board")
            for conn in surface_cells(gmsh, t, index):
                key = "quad4" if conn.shape[1] == 4 else "tri3"
                cells.setdefault(label, {}).setdefault(key, []).append(conn)
        return folded, (xyz, cells, tagged_nodes(gmsh, point_tags, index))


def used_nodes(xyz, cells) -> tuple:
    """(the nodes the cells use (k, 3), old row -> new row or -1): ``cells`` ({label: {etype: [conn, ...]}})
    concatenated and renumbered in place onto them (gmsh keeps construction points)."""
    used = np.zeros(len(xyz), dtype=bool)
    for c in cells.values():
        for k in c:
            c[k] = np.concatenate(c[k])
            used[c[k].ravel()] = True
    new = np.where(used, np.cumsum(used) - 1, -1)
    for c in cells.values():
        for k in c:
            c[k] = new[c[k]]
    return xyz[used].copy(), new


def _signed_area(xyz, conn):
    p = xyz[conn][:, :, :2]
    q = np.roll(p, -1, axis=1)
    return 0.5 * np.sum(p[:, :, 0] * q[:, :, 1] - q[:, :, 0] * p[:, :, 1], axis=1)


def _counter_clockwise(xyz, conn):
    """Cells ordered so their normal is +z."""
    conn = conn.copy()
    flip = _signed_area(xyz, conn) < 0
    conn[flip] = conn[flip][:, ::-1]
    return conn


def quality(mesh: BoardMesh) -> dict:
    """Counts of quads and triangles and the smallest quad corner angle [deg] (a cheap shape check)."""
    q = mesh.all_cells("quad4")
    t = mesh.all_cells("tri3")
    out = {"quads": len(q), "triangles": len(t), "min_quad_angle_deg": None}
    if len(q):
        p = mesh.nodes[q][:, :, :2]
        a = np.roll(p, 1, axis=1) - p
        b = np.roll(p, -1, axis=1) - p
        cosang = np.sum(a * b, axis=2) / (np.linalg.norm(a, axis=2) * np.linalg.norm(b, axis=2))
        out["min_quad_angle_deg"] = float(np.degrees(np.arccos(np.clip(cosang, -1, 1))).min())
    return out
