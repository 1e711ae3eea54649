"""The geometry of a UFF file in the global frame and SI: nodes (datasets 15, 2411) placed through their
coordinate systems (18, 2420), each node's displacement axes, trace lines (82) and elements (2412) as the
test's wireframe, and the units (164).

A node record names two coordinate systems: the one its coordinates are given in (15: definition, 2411:
export) and the one its measured directions refer to (displacement). Label 0 is the global frame; label 1,
when no dataset defines it, too (I-DEAS' default part frame); any other label must be defined. Test.Lab
gives every node a displacement system of its own (dataset 18, e.g. x along -X, z along -Z), so a
direction code of a mode or an FRF at that node means that system's axis.

A coordinate system is cartesian or cylindrical (x = r, y = theta in degrees, z); its axes are the rows of
R in the global frame (dataset 2420 writes R and the origin as its four rows; dataset 18 gives the origin, a
point on +x and a point in the +xz plane, in its reference system). A displacement system that is
cylindrical gives each node the radial, tangential and axial directions at that node.

Units: dataset 164 gives the length factor. A file without one whose grid spans more than
:data:`MAX_GRID_M` is refused as mm read as metres unless the caller states the file's units
(:func:`stated_units`, the commands' ``--units``)."""

from __future__ import annotations

import contextlib
import contextvars
from dataclasses import dataclass, field

import numpy as np

from ..units import LENGTHS
from .data import Points, TestDataError
from .uff_fields import Cursor, label, numbers

#: [m] a test grid wider than this in a file that states no units is taken for mm (or another small unit)
MAX_GRID_M = 100.0
#: 2412 descriptors of beams: a record of orientation and cross-sections comes before the node labels
BEAMS = {11, 21, 22, 23, 24, 31, 32}
#: 2412 descriptors of solids -> their edges by corner positions (the linear ones)
SOLID_EDGES = {111: [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
               112: [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)],
               115: [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]}

_UNITS = contextvars.ContextVar("pcbdyn_uff_units", default=None)


@contextlib.contextmanager
def stated_units(unit: str | None):
    """Within the block, UFF files without a dataset 164 are read with lengths in ``unit`` (one of
    :data:`pcbdyn.units.LENGTHS`; None: metres, and a grid too wide for metres is refused); files with a 164
    keep their own."""
    if unit is not None and unit not in LENGTHS:
        raise TestDataError(f"length unit '{unit}' is not one of {', '.join(LENGTHS)}")
    token = _UNITS.set(unit)
    try:
        yield
    finally:
        _UNITS.reset(token)


@dataclass
class Frame:
    """A coordinate system: ``kind`` 0 cartesian, 1 cylindrical; ``R`` (3, 3) its axes as rows in the
    global frame; ``origin`` (3,) in file units."""

    kind: int
    R: np.ndarray
    origin: np.ndarray

    def to_global(self, local) -> np.ndarray:
        p = np.asarray(local, float).reshape(-1, 3)
        if self.kind == 1:
            t = np.radians(p[:, 1])
            p = np.column_stack([p[:, 0] * np.cos(t), p[:, 0] * np.sin(t), p[:, 2]])
        return p @ self.R + self.origin

    def axes_at(self, xyz) -> np.ndarray:
        """(n, 3, 3): the directions 1, 2, 3 of a displacement at each global point, as rows."""
        xyz = np.asarray(xyz, float).reshape(-1, 3)
        if self.kind == 0:
            return np.broadcast_to(self.R, (len(xyz), 3, 3)).copy()
        local = (xyz - self.origin) @ self.R.T
        t = np.arctan2(local[:, 1], local[:, 0])
        c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
        rot = np.stack([np.column_stack([c, s, z]), np.column_stack([-s, c, z]), np.column_stack([z, z, o])], axis=1)
        return rot @ self.R


GLOBAL = Frame(0, np.eye(3), np.zeros(3))


@dataclass
class Geometry:
    """A file's points [m] in the global frame, the displacement axes (3, 3) of every node whose system is not
    the global one, the wireframe (n, 2) of point ids (trace lines and element edges), the elements
    [(descriptor, node labels)] and the length and force factors (file value = SI value * factor) the file
    was read with: its dataset 164's, else the stated units' (:func:`stated_units`)."""

    points: Points
    axes: dict = field(default_factory=dict)
    wireframe: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    elements: list = field(default_factory=list)
    length: float = 1.0
    force: float = 1.0

    def direction(self, node: int, code: int) -> np.ndarray:
        """The global unit direction of UFF direction code +-1..3 at ``node`` (its displacement axes)."""
        A = self.axes.get(int(node))
        axis = np.eye(3)[abs(int(code)) - 1] if A is None else A[abs(int(code)) - 1]
        return np.sign(code) * axis


# ---------------------------------------------------------------------------------------- datasets

_NODE_FIELDS = {4: "label, two coordinate systems, colour", 3: "x, y, z",
                7: "label, two coordinate systems, colour, x, y, z"}


def parse_nodes(raw: bytes, t: int) -> dict:
    """Dataset 2411 (4 integers on one line, x y z on the next, per node) or 15 (all 7 on one line)."""
    shape = (4, 3) if t == 2411 else (7,)
    rows, part = [], []
    for k, line in enumerate(raw.splitlines()[2:], start=3):
        if not line.strip():
            continue
        v = numbers(line, f"line {k} of the dataset")
        want = shape[len(part)]
        if len(v) != want:
            raise TestDataError(f"line {k} of the dataset has {len(v)} values; {want} expected ({_NODE_FIELDS[want]})")
        part.append(v)
        if len(part) == len(shape):
            rows.append(sum(part, []))
            part = []
    if part:
        raise TestDataError(f"node {int(part[0][0])} has no coordinates line (the dataset ends after its label line)")
    v = np.array(rows, dtype=float).reshape(-1, 7)
    for n, a, b in v[:, :3]:
        label(n, "a node record")
        _whole(a, f"node {int(n)}: its coordinate system")
        _whole(b, f"node {int(n)}: its displacement coordinate system")
    return {"type": t, "node_nums": v[:, 0].astype(np.int64), "def_cs": v[:, 1].astype(np.int64),
            "disp_cs": v[:, 2].astype(np.int64), "xyz": v[:, 4:7]}


def parse164(raw: bytes) -> dict:
    """Dataset 164: units code (record 1) and the four factors to SI (record 2)."""
    lines = raw.splitlines()
    if len(lines) < 4:
        raise TestDataError("the dataset is shorter than its two records")
    try:
        code = int(lines[2][:10])
    except ValueError:
        raise TestDataError(f"record 1 '{lines[2][:10].decode('latin-1')}' is not a units code") from None
    f = Cursor(lines[3:], 3).take(4, "record 2 (length, force, temperature, offset)")
    if not (f[0] > 0 and f[1] > 0 and f[2] > 0):
        raise TestDataError(f"record 2: the length, force and temperature factors must be above 0, got {f[:3]} (a "
                            "file in SI has 1.0 for each)")
    return {"type": 164, "units_code": code, "length": f[0], "force": f[1], "temp": f[2], "temp_offset": f[3]}


def _whole(v: float, what: str) -> int:
    """A record's integer field: a whole number from 0 to 2^31 - 1 (the standard's I10)."""
    if not (v == int(v) and 0 <= v < 2**31):
        raise TestDataError(f"{what} {v:g} is not a whole number from 0 to 2147483647")
    return int(v)


def parse18(raw: bytes) -> dict:
    """Dataset 18 (coordinate systems by three points): per system its label, type, reference system and
    the origin, a point on +x and a point in the +xz plane (9 values, in the reference system)."""
    lines = raw.splitlines()
    systems, i = [], 2
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        head = numbers(lines[i], f"record 1, line {i + 1} of the dataset")
        if len(head) != 5:
            raise TestDataError(f"record 1, line {i + 1} of the dataset has {len(head)} values; 5 expected (label, "
                                "type, reference system, colour, method of definition)")
        cs, kind, ref, _, method = (_whole(v, "record 1: a field") for v in head)
        if method != 1:
            raise TestDataError(f"coordinate system {cs}: method of definition {method}; the standard defines only 1 "
                                "(origin, a point on +x, a point in the +xz plane)")
        if i + 2 >= len(lines):
            raise TestDataError(f"coordinate system {cs}: the dataset ends before its three points (records 3, 4)")
        cur = Cursor(lines[i + 2:], i + 2)
        p = np.array(cur.take(9, f"coordinate system {cs}, records 3-4")).reshape(3, 3)
        systems.append({"label": cs, "kind": kind, "ref": ref, "points": p})
        i += 2 + cur.i
    return {"type": 18, "systems": systems}


def parse2420(raw: bytes) -> dict:
    """Dataset 2420 (coordinate systems by matrix): per system its label, type, axes R (rows) and origin."""
    lines = raw.splitlines()
    systems, i = [], 4  # records 1 and 2: the part's number and name
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        head = numbers(lines[i], f"record 3, line {i + 1} of the dataset")
        if len(head) not in (3, 4):
            raise TestDataError(f"record 3, line {i + 1} of the dataset has {len(head)} values; 3 expected (label, "
                                "type, colour)")
        cs, kind = _whole(head[0], "record 3: the label"), _whole(head[1], "record 3: the type")
        if i + 2 >= len(lines):
            raise TestDataError(f"coordinate system {cs}: the dataset ends before its matrix (records 5-8)")
        cur = Cursor(lines[i + 2:], i + 2)
        T = np.array(cur.take(12, f"coordinate system {cs}, records 5-8")).reshape(4, 3)
        systems.append({"label": cs, "kind": kind, "R": T[:3], "origin": T[3]})
        i += 2 + cur.i
    return {"type": 2420, "systems": systems}


def parse82(raw: bytes) -> dict:
    """Dataset 82 (a trace line): its node labels in order, 0 lifting the pen."""
    lines = raw.splitlines()
    if len(lines) < 4:
        raise TestDataError("the dataset is shorter than its records 1 and 2")
    head = numbers(lines[2], "record 1")
    if len(head) < 2:
        raise TestDataError("record 1 holds no number of nodes (trace line number, number of nodes, colour)")
    n = _whole(head[1], "record 1: the number of nodes")
    vals = [v for k, line in enumerate(lines[4:], start=5) for v in numbers(line, f"record 3, line {k} of the dataset")]
    if len(vals) < n or any(vals[n:]):
        raise TestDataError(f"record 3 holds {len(vals)} node labels; record 1 announces {n}")
    return {"type": 82, "nodes": [label(v, "record 3") if v else 0 for v in vals[:n]]}


def parse2412(raw: bytes) -> dict:
    """Dataset 2412 (elements): per element its descriptor and node labels (beams: after their record 2)."""
    lines = raw.splitlines()
    out, cur = [], Cursor(lines[2:], 2)
    last = max((k for k, line in enumerate(lines[2:]) if line.strip()), default=-1)
    while cur.i <= last:
        head = cur.take(6, "record 1 of an element (label, descriptor, property, material, colour, nodes)")
        el, desc, n = (_whole(head[k], "record 1: a field") for k in (0, 1, 5))
        if desc in BEAMS:
            cur.take(3, f"element {el}, record 2 (orientation node, cross-sections)")
        labels = cur.take(n, f"element {el}'s node labels")
        out.append((desc, [label(v, f"element {el}") for v in labels]))
    return {"type": 2412, "elements": out}


PARSERS = {15: lambda raw: parse_nodes(raw, 15), 2411: lambda raw: parse_nodes(raw, 2411), 164: parse164,
           18: parse18, 2420: parse2420, 82: parse82, 2412: parse2412}


# ---------------------------------------------------------------------------------------- assembly


def _frames(dsets) -> dict:
    """{label: Frame} of every 18 and 2420 dataset, 18's systems resolved through their reference systems."""
    frames, pending = {0: GLOBAL}, []
    for d in dsets:
        for s in d.get("systems", ()):
            if s["label"] in frames or any(p["label"] == s["label"] for p in pending):
                raise TestDataError(f"coordinate system {s['label']} is defined twice")
            if s["kind"] not in (0, 1, 2):
                raise TestDataError(f"coordinate system {s['label']}: type {s['kind']} is not cartesian (0), "
                                    "cylindrical (1) or spherical (2)")
            if "R" in s:
                frames[s["label"]] = _checked(s["label"], s["kind"], s["R"], s["origin"])
            else:
                pending.append(s)
    while pending:
        ready = [s for s in pending if s["ref"] in frames or (s["ref"] == 1 and not _defines(pending, 1))]
        if not ready:
            raise TestDataError(f"coordinate system {pending[0]['label']} refers to system {pending[0]['ref']}, "
                                "which no dataset 18 or 2420 defines (or the references form a loop)")
        for s in ready:
            o, px, pxz = frames.get(s["ref"], GLOBAL).to_global(s["points"])
            x = px - o
            y = np.cross(pxz - o, x)  # the normal of the xz plane, on the side that makes z point to pxz
            R = np.array([x, y, np.cross(x, y)])
            norms = np.linalg.norm(R, axis=1)
            if not np.all(norms > 1e-12 * max(1.0, np.abs(s["points"]).max())):
                raise TestDataError(f"coordinate system {s['label']}: its three points are on one line; give the "
                                    "origin, a point on +x and a point off that axis in the +xz plane")
            frames[s["label"]] = _checked(s["label"], s["kind"], R / norms[:, None], o)
            pending.remove(s)
    return frames


def _defines(systems, lab) -> bool:
    return any(s["label"] == lab for s in systems)


def _checked(lab: int, kind: int, R, origin) -> Frame:
    R, origin = np.asarray(R, float), np.asarray(origin, float)
    if not (np.allclose(R @ R.T, np.eye(3), atol=1e-6) and np.linalg.det(R) > 0):
        raise TestDataError(f"coordinate system {lab}: its axes are not a right-handed orthonormal set (records 5-7 "
                            "of dataset 2420 are the unit x, y and z axes)")
    return Frame(kind, R, origin)


def _frame(frames, lab: int, node: int, what: str) -> Frame:
    f = frames.get(lab, GLOBAL if lab == 1 else None)
    if f is None:
        raise TestDataError(f"node {node}: its {what} coordinate system {lab} is not defined; add its dataset 18 or "
                            "2420, or give the node in system 0 (global)")
    if f.kind == 2:
        raise TestDataError(f"node {node}: its {what} coordinate system {lab} is spherical, which pcbdyn does not "
                            "read; export the geometry in cartesian or cylindrical systems")
    return f


def _snap(A: np.ndarray) -> np.ndarray:
    """Axes within 1e-6 of a global axis made exactly that axis (files write -8.7e-8 for 0)."""
    A = np.where(np.abs(A) < 1e-6, 0.0, A)
    return np.where(np.abs(np.abs(A) - 1) < 1e-6, np.sign(A), A)


def _wireframe(dsets, ids) -> tuple:
    """((n, 2) edges between known points, elements) of the trace lines and elements; a label no node has is
    an error naming the dataset kind."""
    edges, elements = [], []
    for d in dsets:
        if d["type"] == 82:
            seq = d["nodes"]
            edges += [(a, b) for a, b in zip(seq[:-1], seq[1:]) if a and b and a != b]
        elif d["type"] == 2412:
            for desc, nodes in d["elements"]:
                elements.append((desc, nodes))
                if desc in SOLID_EDGES:
                    edges += [(nodes[a], nodes[b]) for a, b in SOLID_EDGES[desc] if b < len(nodes)]
                elif desc in BEAMS or len(nodes) < 3:
                    edges += list(zip(nodes[:-1], nodes[1:]))
                elif desc < 100:
                    edges += list(zip(nodes, nodes[1:] + nodes[:1]))
    e = np.array(edges, dtype=np.int64).reshape(-1, 2)
    e = np.unique(np.sort(e, axis=1), axis=0)  # an edge two elements share, drawn once
    unknown = np.setdiff1d(e.ravel(), ids)
    if unknown.size:
        raise TestDataError(f"trace lines (82) or elements (2412) name nodes {unknown[:10].tolist()} that no node "
                            "dataset (15, 2411) gives; export the geometry with them")
    return e, elements


def geometry(dsets, path) -> Geometry:
    """The :class:`Geometry` of the parsed datasets of file ``path`` (nodes, systems, lines, elements, 164)."""
    units = [d for d in dsets if d["type"] == 164]
    length = float(units[0]["length"]) if units else None
    force = float(units[0]["force"]) if units else 1.0
    frames = _frames([d for d in dsets if d["type"] in (18, 2420)])
    nodes = [d for d in dsets if d["type"] in (15, 2411)]
    ids, xyz, axes = [], [], {}
    for d in nodes:
        for n, dcs, pcs, p in zip(d["node_nums"], d["def_cs"], d["disp_cs"], d["xyz"]):
            g = _frame(frames, int(dcs), int(n), "definition" if d["type"] == 15 else "export").to_global(p)[0]
            ids.append(int(n))
            xyz.append(g)
            if pcs not in (0, 1) or pcs in frames:
                A = _snap(_frame(frames, int(pcs), int(n), "displacement").axes_at(g)[0])
                if not np.array_equal(A, np.eye(3)):
                    axes[int(n)] = A
    xyz = np.array(xyz, float).reshape(-1, 3)
    scale = length if length is not None else 1.0 / LENGTHS[_UNITS.get() or "m"]
    pts = Points(np.array(ids, np.int64), xyz / scale)
    if length is None and _UNITS.get() is None and len(pts):
        width = float(np.ptp(pts.xyz, axis=0).max())
        if width > MAX_GRID_M:
            raise TestDataError(f"{path}: the test grid is {width:g} m wide and the file states no units (no dataset "
                                "164): its coordinates look like mm; read it with --units mm (or the unit they are "
                                "in), or add a dataset 164")
    wire, elements = _wireframe(dsets, pts.ids)
    return Geometry(pts, axes, wire, elements, scale, force)
