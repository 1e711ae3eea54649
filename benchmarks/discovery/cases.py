"""Discovery cases drawn from a seed (issue 37): a structure pcbdyn has never seen, its declared
values off, and 0-2 effects its description lacks.

A case is plain data (:class:`Case`, JSON-ready) from which :mod:`toml_text` writes the board.toml
handed to ``pcbdyn diagnose`` (nominal values, ``[[parameters]]`` for what is uncertain) and the
true one (true values, the hidden effects declared as board entries), and :mod:`make` solves the
truth in another FE code. Everything is drawn from ``numpy.random.default_rng(seed)``: places
uniform over the structure (never snapped to a grid or a node), magnitudes log-uniform from
undetectable to large. Seeds 0-199 are the development split, 1000-1199 the report split.

Boards: rectangles, L and notched outlines 60-250 mm a side, 0.8-3.2 mm of an FR-4 or a
polyimide-like laminate, 0-15 parts of six families (equivalent-thickness regions, lumped bodies
with their height, spread masses, stiff smeared regions), held free, on 3-6 standoffs, in two
wedge-lock guides, on clamped or hinged edges, or a mixture. Hidden effects: point masses,
brackets (a mass on a spring to the frame), springs to ground, undeclared rigid standoffs, bars
with their mass that need not span the board (any direction), heat sinks (mass and local
stiffness), line masses, stiffness on part of a held edge, stiffer or softer regions.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
import shapely

DEV = range(0, 200)
REPORT = range(1000, 1200)

#: laminates: (name, E [Pa] range, nu, rho [kg/m^3])
LAMINATES = [("FR-4", (18e9, 27e9), 0.15, 1900.0), ("polyimide", (12e9, 20e9), 0.2, 1700.0)]
#: part families: footprint side range [mm] (square, or (a, b) ranges for rectangles), areal mass
#: [kg/m^2] or mass [kg] range, model
FAMILIES = {
    "BGA": dict(side=(10, 35), areal=(2.5, 6.0), model="equivalent_thickness"),
    "QFP": dict(side=(10, 30), areal=(1.5, 4.0), model="equivalent_thickness"),
    "SOIC": dict(rect=((4, 8), (6, 18)), mass=(0.1e-3, 0.8e-3), model="lumped", height=(1.5, 2.5)),
    "CAP": dict(side=(5, 16), mass=(1e-3, 12e-3), model="lumped", height=(8, 25)),
    "CONN": dict(rect=((6, 12), (20, 60)), mass=(3e-3, 20e-3), model="spread"),
    "XFMR": dict(side=(12, 30), mass=(8e-3, 40e-3), model="smeared_local"),
}
#: hidden effect kinds on boards and their weights
BOARD_EFFECTS = {"point_mass": 0.18, "bracket": 0.10, "ground_spring": 0.10, "standoff": 0.04, "stiffener": 0.15,
                 "heat_sink": 0.10, "line_mass": 0.12, "edge_stiffness": 0.08, "region": 0.13}
HOLDS = {"free": 0.25, "standoffs": 0.25, "guides": 0.25, "edges": 0.15, "mixed": 0.10}
NOISE = (0.2, 2.0)  # (frequency %, shape %), uniform bounds as pcbdyn states them
TEST_MODES = 10


@dataclass
class Case:
    """A drawn case; lengths in mm, other quantities SI (as their keys say)."""

    seed: int
    family: str
    outline: list  # polygon [[x, y], ...] mm
    thickness_mm: float
    laminate: str
    E: float
    nu: float
    rho: float
    mesh_mm: float
    parts: list = field(default_factory=list)
    fixtures: list = field(default_factory=list)
    parameters: list = field(default_factory=list)  # {name, targets, unit, nominal, true, bounds}
    effects: list = field(default_factory=list)
    points: list = field(default_factory=list)  # [[x, y], ...] mm
    noise: tuple = NOISE
    test_modes: int = TEST_MODES
    shell: str = "ShellDKGQ"
    hold: str = "free"

    @property
    def name(self) -> str:
        return f"s{self.seed:04d}"

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, d: dict) -> "Case":
        return cls(**d)


def _loguniform(rng, lo, hi) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _outline(rng) -> list:
    W, H = rng.uniform(60, 250, size=2)
    shape = rng.choice(["rect", "rect", "L", "notch"])
    if shape == "L":
        a, b = W * rng.uniform(0.25, 0.45), H * rng.uniform(0.25, 0.45)
        poly = [(0, 0), (W, 0), (W, H - b), (W - a, H - b), (W - a, H), (0, H)]
    elif shape == "notch":
        a, b = W * rng.uniform(0.15, 0.3), H * rng.uniform(0.1, 0.25)
        c = rng.uniform(0.1 * W, 0.9 * W - a)
        poly = [(0, 0), (W, 0), (W, H), (c + a, H), (c + a, H - b), (c, H - b), (c, H), (0, H)]
    else:
        poly = [(0, 0), (W, 0), (W, H), (0, H)]
    return [[round(float(x), 2), round(float(y), 2)] for x, y in poly]


def _free_spot(rng, room, size, taken, tries=200):
    """A centre where a footprint ``size`` (w, h) [mm] lies inside ``room`` (shapely) clear of ``taken``."""
    lo_x, lo_y, hi_x, hi_y = room.bounds
    for _ in range(tries):
        c = rng.uniform([lo_x, lo_y], [hi_x, hi_y])
        box = shapely.box(c[0] - size[0] / 2, c[1] - size[1] / 2, c[0] + size[0] / 2, c[1] + size[1] / 2)
        if room.contains(box) and not any(box.intersects(t) for t in taken):
            return c, box
    return None, None


def _parts(rng, case: Case, board, t_mm):
    """0-15 parts; one thickness per equivalent-thickness family (so that one parameter drives them)."""
    n = int(rng.integers(0, 16))
    taken, per_family = [], {}
    room = board.buffer(-2.0)
    for i in range(n):
        fam = str(rng.choice(list(FAMILIES)))
        spec = FAMILIES[fam]
        if "rect" in spec:
            (a0, a1), (b0, b1) = spec["rect"]
            size = [float(rng.uniform(a0, a1)), float(rng.uniform(b0, b1))]
            if rng.random() < 0.5:
                size.reverse()
        else:
            s = float(rng.uniform(*spec["side"]))
            size = [s, s]
        c, box = _free_spot(rng, room, size, taken)
        if c is None:
            continue
        taken.append(box.buffer(0.5))
        mass = (float(rng.uniform(*spec["areal"])) * size[0] * size[1] * 1e-6 if "areal" in spec
                else _loguniform(rng, *spec["mass"]))
        part = {"ref": f"U{i + 1}", "family": fam, "at": [round(float(c[0]), 2), round(float(c[1]), 2)],
                "size": [round(size[0], 2), round(size[1], 2)], "mass": mass, "model": spec["model"]}
        if "height" in spec:
            part["height_mm"] = round(float(rng.uniform(*spec["height"])), 2)
        if spec["model"] == "equivalent_thickness":
            per_family.setdefault(fam, round(t_mm * float(rng.uniform(1.3, 2.5)), 3))
            part["thickness_mm"] = per_family[fam]
        if spec["model"] == "smeared_local":
            part["E"] = case.E * float(rng.uniform(1.5, 3.0))
        case.parts.append(part)
    return taken, per_family


def _hold(rng, case: Case, board):
    """The fixtures of the handed (and true) board; returns the held edges [(edge, line segment mm)]."""
    hold = str(rng.choice(list(HOLDS), p=list(HOLDS.values())))
    case.hold = hold
    W, H = board.bounds[2], board.bounds[3]
    held = []

    def standoffs(n):
        inset = 6.0
        corners = [(inset, inset), (W - inset, inset), (W - inset, H - inset), (inset, H - inset)]
        pts = [c for c in corners if board.buffer(-4.0).contains(shapely.Point(c))]
        while len(pts) < n:
            p = rng.uniform([inset, inset], [W - inset, H - inset])
            if board.buffer(-4.0).contains(shapely.Point(p)):
                pts.append(tuple(p))
        rng.shuffle(pts)
        return [[round(float(x), 2), round(float(y), 2)] for x, y in pts[:n]]

    def edge_pair(kind):
        axis = int(rng.integers(0, 2))
        lines = [("x=0", ((0, 0), (0, H))), (f"x={W:g} mm", ((W, 0), (W, H)))] if axis == 0 else \
                [("y=0", ((0, 0), (W, 0))), (f"y={H:g} mm", ((0, H), (W, H)))]
        return [(kind, e, seg) for e, seg in lines]

    if hold in ("standoffs", "mixed"):
        rigid = rng.random() < 0.5
        k = None if rigid else _loguniform(rng, 3e4, 3e6)
        for j, at in enumerate(standoffs(int(rng.integers(3, 7)) if hold == "standoffs" else 2)):
            case.fixtures.append({"name": f"so{j + 1}", "type": "standoff", "at": at, "k": k})
        if k is not None:
            _parameter(rng, case, "k_standoffs", [f"fixtures.so{j + 1}.k" for j in range(len(case.fixtures))],
                       "N/m", k, log=True)
    if hold in ("guides", "mixed"):
        k = _loguniform(rng, 3e2, 3e4)
        pair = edge_pair("wedge_lock")
        if hold == "mixed":
            pair = pair[:1]
        for j, (typ, e, seg) in enumerate(pair):
            case.fixtures.append({"name": f"guide{j + 1}", "type": typ, "edge": e, "k_rot": k})
            held.append((e, seg, typ))
        _parameter(rng, case, "k_guides", [f"fixtures.guide{j + 1}.k_rot" for j in range(len(pair))],
                   "N*m/rad/m", k, log=True)
    if hold == "edges":
        pair = edge_pair(str(rng.choice(["clamped_edge", "hinged_edge"])))
        if rng.random() < 0.5:  # one edge: clamped (hinged alone, the board would turn about it)
            pair = [("clamped_edge", e, seg) for _, e, seg in pair[:1]]
        for j, (typ, e, seg) in enumerate(pair):
            case.fixtures.append({"name": f"edge{j + 1}", "type": typ, "edge": e})
            held.append((e, seg, typ))
    return held


def _parameter(rng, case: Case, name, targets, unit, nominal, log=False) -> None:
    """A declared parameter at ``nominal`` whose truth is a few % to 40 % off (either way)."""
    off = _loguniform(rng, 0.03, 0.40) * (1 if rng.random() < 0.5 else -1)
    true = nominal * (1.0 + off) if off > 0 or not log else nominal / (1.0 - off)
    lo, hi = (nominal / 100.0, nominal * 100.0) if log else (nominal * 0.4, nominal * 2.5)
    case.parameters.append({"name": name, "targets": targets, "unit": unit, "nominal": nominal, "true": true,
                            "bounds": [lo, hi]})


def _segment_in(rng, room, length_range, tries=200):
    """A straight segment [[x, y], [x, y]] mm of a length drawn from ``length_range``, in ``room``."""
    for _ in range(tries):
        L = rng.uniform(*length_range)
        a = rng.uniform(room.bounds[:2], room.bounds[2:])
        th = rng.uniform(0, np.pi)
        b = a + L * np.array([np.cos(th), np.sin(th)])
        if room.contains(shapely.LineString([a, b])):
            return [[round(float(v), 2) for v in a], [round(float(v), 2) for v in b]]
    return None


def _on_edge(rng, board, frac=(0.2, 0.6)):
    """A stretch of a straight piece of the outline: [[x, y], [x, y]] mm."""
    ring = np.asarray(board.exterior.coords)[:-1]
    pieces = [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
    lengths = np.array([np.linalg.norm(b - a) for a, b in pieces])
    i = int(rng.choice(len(pieces), p=lengths / lengths.sum()))
    a, b = pieces[i]
    f = rng.uniform(*frac)
    s = rng.uniform(0, 1 - f)
    p, q = a + s * (b - a), a + (s + f) * (b - a)
    return [[round(float(v), 2) for v in p], [round(float(v), 2) for v in q]]


def _effect(rng, case: Case, kind: str, board, taken, held):
    """One hidden effect of ``kind`` (None where it does not fit this structure)."""
    inner = board.buffer(-3.0)

    def point():
        while True:
            p = rng.uniform(inner.bounds[:2], inner.bounds[2:])
            if inner.contains(shapely.Point(p)):
                return [round(float(p[0]), 2), round(float(p[1]), 2)]

    if kind == "point_mass":
        return {"kind": kind, "at": point(), "mass": _loguniform(rng, 0.3e-3, 60e-3)}
    if kind == "bracket":
        return {"kind": kind, "at": point(), "mass": _loguniform(rng, 2e-3, 40e-3), "k": _loguniform(rng, 2e3, 5e5)}
    if kind == "ground_spring":
        return {"kind": kind, "at": point(), "k": _loguniform(rng, 1e3, 3e6)}
    if kind == "standoff":
        spot = board.buffer(-6.0)
        if spot.is_empty:
            return None
        while True:
            p = rng.uniform(spot.bounds[:2], spot.bounds[2:])
            if spot.contains(shapely.Point(p)):
                return {"kind": kind, "at": [round(float(p[0]), 2), round(float(p[1]), 2)]}
    if kind == "stiffener":
        span = max(board.bounds[2], board.bounds[3])
        seg = _segment_in(rng, inner, (0.3 * span, 1.0 * span))
        if seg is None:
            return None
        steel = rng.random() < 0.5
        E, rho = (200e9, 7850.0) if steel else (70e9, 2700.0)
        w, h = _loguniform(rng, 2.0, 12.0), _loguniform(rng, 1.0, 6.0)
        return {"kind": kind, "path": seg, "material": "steel" if steel else "aluminium", "E": E, "rho": rho,
                "width_mm": round(w, 3), "height_mm": round(h, 3), "EI": E * (w * 1e-3) * (h * 1e-3) ** 3 / 12.0}
    if kind == "heat_sink":
        s = float(rng.uniform(12, 45))
        c, box = _free_spot(rng, board.buffer(-2.0), (s, s), taken)
        if c is None:
            return None
        taken.append(box.buffer(0.5))
        return {"kind": kind, "at": [round(float(c[0]), 2), round(float(c[1]), 2)], "size": [round(s, 2)] * 2,
                "mass": _loguniform(rng, 3e-3, 60e-3), "E": case.E * _loguniform(rng, 1.5, 8.0)}
    if kind == "line_mass":
        seg = _on_edge(rng, board) if rng.random() < 0.6 else _segment_in(rng, inner, (20, 80))
        if seg is None:
            return None
        return {"kind": kind, "segment": seg, "mass": _loguniform(rng, 3e-3, 40e-3)}
    if kind == "edge_stiffness":
        usable = [(e, seg) for e, seg, typ in held if typ in ("wedge_lock", "hinged_edge")]
        if not usable:
            return None
        e, (a, b) = usable[int(rng.integers(len(usable)))]
        a, b = np.asarray(a, float), np.asarray(b, float)
        f = rng.uniform(0.3, 0.7)
        s = rng.uniform(0, 1 - f)
        line = shapely.LineString([a + s * (b - a), a + (s + f) * (b - a)]).intersection(board.exterior)
        if line.is_empty or line.geom_type != "LineString" or line.length < 10:
            return None
        seg = np.asarray(line.coords)[[0, -1]]
        return {"kind": kind, "segment": np.round(seg, 2).tolist(), "k_rot": _loguniform(rng, 30.0, 3e4)}
    if kind == "region":
        a, b = rng.uniform(15, 60, size=2)
        c, box = _free_spot(rng, board.buffer(-1.0), (a, b), [])
        if c is None:
            return None
        factor = _loguniform(rng, 0.3, 0.8) if rng.random() < 0.4 else _loguniform(rng, 1.25, 5.0)
        return {"kind": kind, "rect": np.round(box.bounds, 2).tolist(), "factor": factor}
    raise ValueError(kind)


def _points(rng, board, n_target: int) -> list:
    """About ``n_target`` measurement points: a jittered grid over the outline (3 mm in)."""
    inner = board.buffer(-3.0)
    x0, y0, x1, y1 = inner.bounds
    aspect = (x1 - x0) / (y1 - y0)
    frac = inner.area / ((x1 - x0) * (y1 - y0))
    nx = max(3, int(round(math.sqrt(n_target / frac * aspect))))
    ny = max(3, int(round(n_target / frac / nx)))
    dx, dy = (x1 - x0) / nx, (y1 - y0) / ny
    out = []
    for i in range(nx):
        for j in range(ny):
            p = (x0 + (i + 0.5 + rng.uniform(-0.3, 0.3)) * dx, y0 + (j + 0.5 + rng.uniform(-0.3, 0.3)) * dy)
            if inner.contains(shapely.Point(p)):
                out.append([round(float(p[0]), 3), round(float(p[1]), 3)])
    return out


def draw(seed: int) -> Case:
    """The case of ``seed``."""
    rng = np.random.default_rng(seed)
    outline = _outline(rng)
    board = shapely.Polygon(outline)
    lam, (E0, E1), nu, rho = LAMINATES[int(rng.integers(len(LAMINATES)))]
    t = round(float(rng.uniform(0.8, 3.2)), 2)
    span = max(board.bounds[2], board.bounds[3])
    h = float(np.clip(round(span / 30.0 * 2) / 2, 3.0, 8.0))
    case = Case(seed, "board", outline, t, lam, float(rng.uniform(E0, E1)), nu, rho, h,
                shell="ShellDKGQ" if rng.random() < 0.5 else "ASDShellQ4")
    taken, families = _parts(rng, case, board, t)
    held = _hold(rng, case, board)
    _parameter(rng, case, "E_board", ["board.E"], "Pa", case.E)
    for fam, t_eq in families.items():
        refs = [p["ref"] for p in case.parts if p["family"] == fam]
        _parameter(rng, case, f"t_{fam}", [f"components.{r}.thickness" for r in refs], "mm", 1e-3 * t_eq)
    n_eff = int(rng.choice([0, 1, 2], p=[0.25, 0.45, 0.30]))
    kinds = list(BOARD_EFFECTS)
    while len(case.effects) < n_eff:
        k = str(rng.choice(kinds, p=np.array(list(BOARD_EFFECTS.values())) / sum(BOARD_EFFECTS.values())))
        e = _effect(rng, case, k, board, taken, held)
        if e is not None:
            e["name"] = f"hidden{len(case.effects) + 1}"
            case.effects.append(e)
    case.points = _points(rng, board, int(rng.integers(20, 121)))
    return case
