"""board.toml -> plain dataclasses (SI units), with one clear message per problem.

Every message names the file and the field (e.g. ``board.toml: components[2].at``) and says how
to fix it. Geometric checks (parts on the board, parts not overlapping, fixture edges on the
outline, parameter targets and bounds) are done here so that a bad file never reaches the mesher.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.path import Path as PolyPath

from ..components.library import MODELS, LibraryError, Package, available, find_package
from ..units import UnitError, to_si
from .laminate import MATERIALS, LaminateProperty, Layer, Material

FIXTURE_TYPES = ("free", "clamped_edge", "hinged_edge", "wedge_lock", "standoff", "point_spring", "edge_spring")
MIN_SEGMENT = 1e-4  # [m] shortest segment of an edge spring, line mass or stiffener piece
GEOM_TOL = 1e-7  # [m] touching footprints or points on an edge are accepted within this


class BoardError(ValueError):
    """A board description that cannot be used; the message names the file, the field and the fix."""


# ----------------------------------------------------------------------------- dataclasses
@dataclass
class Outline:
    """Board outline in the board frame (origin at the lower-left corner of the bounding box)."""

    vertices: np.ndarray  # (n, 2) counter-clockwise
    holes: list = field(default_factory=list)  # list of (m, 2) arrays
    is_rectangle: bool = False

    @property
    def bbox(self):
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    def area(self) -> float:
        def shoelace(v):
            x, y = v[:, 0], v[:, 1]
            return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

        return shoelace(self.vertices) - sum(shoelace(h) for h in self.holes)

    def contains(self, pts, tol=GEOM_TOL) -> np.ndarray:
        """True for points on the board (boundary included, holes excluded)."""
        pts = np.atleast_2d(pts)
        inside = PolyPath(self.vertices).contains_points(pts, radius=tol) | PolyPath(
            self.vertices).contains_points(pts, radius=-tol)
        for h in self.holes:
            inside &= ~PolyPath(h).contains_points(pts, radius=-tol) & ~PolyPath(h).contains_points(pts, radius=tol)
        return inside

    def edge_extent(self, axis: int, value: float, tol=GEOM_TOL):
        """(lo, hi) of the outline's boundary lying on the line x=value (axis 0) or y=value (axis 1),
        or None when no outline segment lies on it."""
        v = self.vertices
        w = np.roll(v, -1, axis=0)
        on = (np.abs(v[:, axis] - value) < tol) & (np.abs(w[:, axis] - value) < tol)
        if not on.any():
            return None
        other = 1 - axis
        seg = np.concatenate([v[on, other], w[on, other]])
        return float(seg.min()), float(seg.max())


@dataclass
class Component:
    ref: str
    at: tuple  # centre (x, y) [m]
    rotation: float  # [rad]
    size: tuple  # footprint (a, b) [m] before rotation
    height: float  # body height [m] (rotary inertia of a lumped part)
    mass: float  # [kg]
    model: str
    thickness: float | None  # equivalent thickness [m] (equivalent_thickness model)
    E: float | None = None  # region Young's modulus (smeared_local); default: the board's
    rho: float | None = None  # region density as given (then it set ``mass``); default: from mass
    package: str | None = None

    def corners(self) -> np.ndarray:
        a, b = self.size
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        local = np.array([[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, b / 2], [-a / 2, b / 2]])
        return np.asarray(self.at) + local @ np.array([[c, s], [-s, c]])

    @property
    def area(self) -> float:
        return self.size[0] * self.size[1]


@dataclass
class Fixture:
    name: str
    type: str
    edge: tuple | None = None  # (axis, value): axis 0 -> "x=value", 1 -> "y=value"
    width: float = 0.0  # contact strip [m]
    k_rot: float | str | None = None  # N m/rad/m, or "clamped" / "hinged"
    at: tuple | None = None
    k: float | str | None = None  # N/m or "rigid"
    diameter: float = 0.0  # standoff pad held rigid [m]
    segment: tuple | None = None  # edge_spring: ((x0, y0), (x1, y1)) [m]


@dataclass
class PointMass:
    name: str
    at: tuple
    mass: float
    inertia: float = 0.0  # rotary inertia about the in-plane axes [kg m^2]


@dataclass
class LineMass:
    """A mass [kg] spread uniformly along a straight segment ((x0, y0), (x1, y1)) [m]."""

    name: str
    segment: tuple
    mass: float


@dataclass
class RibSection:
    """A stiffener's fixed material and height; its width follows from EI (defaults: aluminium,
    4 mm, as the diagnosis ``stiffener`` kind)."""

    E: float = 70e9
    nu: float = 0.33
    rho: float = 2700.0
    h: float = 4e-3


@dataclass
class Stiffener:
    """A rib of bending stiffness EI [N m^2] along ``path`` ((x, y), ...) [m] of straight pieces."""

    name: str
    path: tuple
    EI: float
    section: RibSection = field(default_factory=RibSection)


@dataclass
class Region:
    """Shells inside ``polygon`` (m, 2) [m] get ``stiffness_factor`` times their stiffness."""

    name: str
    polygon: np.ndarray
    stiffness_factor: float


@dataclass
class Configuration:
    name: str
    masses: list


@dataclass
class ParameterSpec:
    name: str
    targets: list
    bounds: tuple
    unit: str


@dataclass
class Analysis:
    modes: int = 12
    f_max: float | None = None


@dataclass
class Board:
    name: str
    path: Path
    outline: Outline
    plate: object  # a ShellProperty-like object for the bare board
    isotropic: Material | None  # the board material when given as one (None for a stack-up)
    mesh_size: float
    smear: str  # "none" or "global" (all part masses spread over the whole board)
    components: list
    fixtures: list
    masses: list
    configurations: list
    parameters: list
    analysis: Analysis
    points: list  # measurement points (x, y) [m] to put nodes on
    line_masses: list = field(default_factory=list)
    stiffeners: list = field(default_factory=list)
    regions: list = field(default_factory=list)

    @property
    def thickness(self) -> float:
        return self.plate.t

    def component(self, ref):
        return next((c for c in self.components if c.ref == ref), None)

    def fixture(self, name):
        return next((f for f in self.fixtures if f.name == name), None)

    def point_mass(self, name):
        return next((m for m in self.masses if m.name == name), None)

    def configuration(self, name):
        return next((c for c in self.configurations if c.name == name), None)

    def entry(self, kind, name):
        """The ``line_masses``, ``stiffeners`` or ``regions`` entry called ``name`` (or None)."""
        return next((e for e in getattr(self, kind) if e.name == name), None)

    def quantity(self, target: str):
        """(current value in SI, unit) of a parameter target such as ``components.U1.thickness``;
        None when the target does not exist."""
        parts = target.split(".")
        if target == "board.transverse_shear":  # a factor on every shell's transverse shear stiffness
            return 1.0, "1"
        if len(parts) == 2 and parts[0] == "board" and self.isotropic is not None:
            attr = {"E": ("E", "Pa"), "rho": ("rho", "kg/m^3")}
            if parts[1] in attr:
                a, u = attr[parts[1]]
                return getattr(self.isotropic, a), u
            if parts[1] == "thickness":
                return self.plate.t, "mm"
            return None
        if len(parts) != 3:
            return None
        kind, name, attr = parts
        if kind == "components" and (c := self.component(name)) is not None and self.smear == "none":
            if attr == "thickness" and c.model == "equivalent_thickness":
                return c.thickness, "mm"
            if attr == "mass":
                return c.mass, "g"
            if attr == "E" and c.model == "smeared_local" and self.isotropic is not None:
                return (c.E if c.E is not None else self.isotropic.E), "Pa"
            if attr == "rho" and c.model == "smeared_local":
                return smeared_density(self, c), "kg/m^3"
            return None
        if kind == "fixtures" and (f := self.fixture(name)) is not None:
            if attr == "k_rot" and f.type == "wedge_lock" and isinstance(f.k_rot, float):
                return f.k_rot, "N*m/rad/m"
            if attr == "k" and f.type in ("standoff", "point_spring") and isinstance(f.k, float):
                return f.k, "N/m"
            if attr == "k_rot" and f.type == "edge_spring":
                return f.k_rot, "N*m/rad/m"
            return None
        if kind == "masses" and (m := self.point_mass(name)) is not None and attr == "mass":
            return m.mass, "g"
        if kind == "line_masses" and (e := self.entry(kind, name)) is not None and attr == "mass":
            return e.mass, "g"
        if kind == "stiffeners" and (e := self.entry(kind, name)) is not None and attr == "EI":
            return e.EI, "N*m^2"
        if kind == "regions" and (e := self.entry(kind, name)) is not None and attr == "stiffness_factor":
            return e.stiffness_factor, "dimensionless"
        return None


def smeared_density(board: Board, c: Component) -> float:
    """Region density of a locally smeared part: the board's plus the part mass over its volume of
    board, so the region carries board + part mass (thesis 7.2.3, local smearing)."""
    t = board.plate.t
    rho_b = board.plate.mass_per_area() / t
    return rho_b + c.mass / (c.area * t)


# ----------------------------------------------------------------------------- reading
class _Reader:
    """Field access with the file name in every message."""

    def __init__(self, path: Path):
        self.file = path.name

    def fail(self, where: str, msg: str):
        raise BoardError(f"{self.file}: {where}: {msg}")

    def table(self, data, where, allowed, required=()):
        if not isinstance(data, dict):
            self.fail(where, "must be a table ({ key = value, ... })")
        for k in data:
            if k not in allowed:
                close = difflib.get_close_matches(k, allowed, n=1)
                hint = f"did you mean '{close[0]}'?" if close else f"allowed: {', '.join(allowed)}"
                self.fail(f"{where}.{k}", f"unknown field; {hint}")
        for k in required:
            if k not in data:
                self.fail(f"{where}.{k}", f"missing; add {k} = ...")
        return data

    def q(self, value, unit, where, positive=False, nonneg=False):
        try:
            v = to_si(value, unit, f"{self.file}: {where}")
        except UnitError as exc:
            raise BoardError(str(exc)) from None
        if positive and not v > 0:
            self.fail(where, f"must be positive, got {value!r}")
        if nonneg and v < 0:
            self.fail(where, f"must not be negative, got {value!r}")
        return v

    def point(self, value, where):
        if not (isinstance(value, list) and len(value) == 2):
            self.fail(where, f"must be a point [\"x mm\", \"y mm\"], got {value!r}")
        return tuple(self.q(v, "mm", f"{where}[{i}]") for i, v in enumerate(value))

    def number(self, value, where, lo=None, hi=None):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(where, f"must be a number, got {value!r}")
        if (lo is not None and value <= lo) or (hi is not None and value >= hi):
            self.fail(where, f"must lie between {lo} and {hi} (exclusive), got {value}")
        return float(value)


def read_toml(path) -> tuple:
    """(text, parsed data) of a TOML file; a BoardError naming the file when it is missing or malformed."""
    path = Path(path)
    if not path.is_file():
        raise BoardError(f"{path}: no such file")
    text = path.read_text()
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise BoardError(f"{path.name}: not valid TOML: {exc}; fix the syntax at that line") from None


def load_board(path) -> Board:
    """Read and validate a board.toml."""
    return parse_board(read_toml(path)[1], Path(path))


def parse_board(data: dict, path: Path) -> Board:
    r = _Reader(Path(path))
    r.table(data, "top level", ["board", "components", "fixtures", "masses", "configurations", "parameters",
                                "analysis", "points", "line_masses", "stiffeners", "regions"], required=["board"])
    b = r.table(data["board"], "board", ["name", "outline", "thickness", "material", "stackup", "mesh_size",
                                         "smear"], required=["outline"])
    outline = _outline(r, b["outline"])
    plate, iso = _plate(r, b)
    mesh_size = r.q(b.get("mesh_size", "5 mm"), "mm", "board.mesh_size", positive=True)
    smear = b.get("smear", "none")
    if smear not in ("none", "global"):
        r.fail("board.smear", f"'{smear}' is not 'none' or 'global' (global: spread every part's mass over the board)")
    board = Board(
        name=str(b.get("name", Path(path).parent.name)), path=Path(path), outline=outline, plate=plate,
        isotropic=iso, mesh_size=mesh_size, smear=smear, components=[], fixtures=[], masses=[],
        configurations=[], parameters=[], analysis=Analysis(), points=[],
    )
    for i, c in enumerate(_list(r, data, "components")):
        board.components.append(_component(r, c, f"components[{i}]", board))
    _check_overlaps(r, board)
    for i, f in enumerate(_list(r, data, "fixtures")):
        board.fixtures.append(_fixture(r, f, f"fixtures[{i}]", board, i))
    _check_edge_springs(r, board)
    for i, m in enumerate(_list(r, data, "masses")):
        board.masses.append(_mass(r, m, f"masses[{i}]", board, f"m{i + 1}"))
    _unique(r, [m.name for m in board.masses], "masses", "name")
    for i, e in enumerate(_list(r, data, "line_masses")):
        board.line_masses.append(_line_mass(r, e, f"line_masses[{i}]", board))
    for i, e in enumerate(_list(r, data, "stiffeners")):
        board.stiffeners.append(_stiffener(r, e, f"stiffeners[{i}]", board))
    for i, e in enumerate(_list(r, data, "regions")):
        board.regions.append(_region(r, e, f"regions[{i}]", board))
    for kind in ("line_masses", "stiffeners", "regions"):
        _unique(r, [e.name for e in getattr(board, kind)], kind, "name")
    for i, c in enumerate(_list(r, data, "configurations")):
        where = f"configurations[{i}]"
        r.table(c, where, ["name", "masses"], required=["name"])
        ms = [_mass(r, m, f"{where}.masses[{j}]", board, f"m{j + 1}")
              for j, m in enumerate(c.get("masses", []))]
        board.configurations.append(Configuration(str(c["name"]), ms))
    _unique(r, [c.name for c in board.configurations], "configurations", "name")
    for i, p in enumerate(data.get("points", [])):
        pt = r.point(p, f"points[{i}]")
        if not outline.contains(pt)[0]:
            r.fail(f"points[{i}]", f"{p} is not on the board; move it inside the outline")
        board.points.append(pt)
    if "analysis" in data:
        a = r.table(data["analysis"], "analysis", ["modes", "f_max"])
        modes = a.get("modes", 12)
        if isinstance(modes, bool) or not isinstance(modes, int) or modes < 1:
            r.fail("analysis.modes", f"must be a positive whole number, got {modes!r}")
        f_max = r.q(a["f_max"], "Hz", "analysis.f_max", positive=True) if "f_max" in a else None
        board.analysis = Analysis(modes, f_max)
    for i, p in enumerate(_list(r, data, "parameters")):
        board.parameters.append(_parameter(r, p, f"parameters[{i}]", board))
    _unique(r, [p.name for p in board.parameters], "parameters", "name")
    return board


def _list(r, data, key):
    v = data.get(key, [])
    if not isinstance(v, list):
        r.fail(key, f"must be an array of tables: write [[{key}]] blocks")
    return v


def _unique(r, names, where, key):
    seen = set()
    for i, n in enumerate(names):
        if n in seen:
            r.fail(f"{where}[{i}].{key}", f"'{n}' is used twice; give each a different {key}")
        seen.add(n)


def _outline(r, o) -> Outline:
    r.table(o, "board.outline", ["width", "height", "polygon", "holes"])
    if "polygon" in o:
        pts = o["polygon"]
        if not isinstance(pts, list) or len(pts) < 3:
            r.fail("board.outline.polygon", "needs at least three points [[\"x mm\", \"y mm\"], ...]")
        v = np.array([r.point(p, f"board.outline.polygon[{i}]") for i, p in enumerate(pts)])
        rect = False
    elif "width" in o and "height" in o:
        w = r.q(o["width"], "mm", "board.outline.width", positive=True)
        h = r.q(o["height"], "mm", "board.outline.height", positive=True)
        v = np.array([[0, 0], [w, 0], [w, h], [0, h]], dtype=float)
        rect = True
    else:
        r.fail("board.outline", "give width and height, or polygon = [[\"x mm\", \"y mm\"], ...]")
    lo = v.min(axis=0)
    v = v - lo
    area2 = np.dot(v[:, 0], np.roll(v[:, 1], -1)) - np.dot(v[:, 1], np.roll(v[:, 0], -1))
    if abs(area2) < 1e-12:
        r.fail("board.outline.polygon", "encloses no area")
    if area2 < 0:
        v = v[::-1]
    holes = []
    for i, h in enumerate(o.get("holes", [])):
        where = f"board.outline.holes[{i}]"
        r.table(h, where, ["polygon", "at", "diameter", "size"])
        if "polygon" in h:
            hv = np.array([r.point(p, f"{where}.polygon[{j}]") for j, p in enumerate(h["polygon"])]) - lo
        elif "at" in h and "diameter" in h:
            c = np.array(r.point(h["at"], f"{where}.at")) - lo
            d = r.q(h["diameter"], "mm", f"{where}.diameter", positive=True)
            ang = np.linspace(0, 2 * np.pi, 16, endpoint=False)
            hv = c + 0.5 * d * np.c_[np.cos(ang), np.sin(ang)]
        elif "at" in h and "size" in h:
            c = np.array(r.point(h["at"], f"{where}.at")) - lo
            a, b = (r.q(s, "mm", f"{where}.size", positive=True) for s in h["size"])
            hv = c + np.array([[-a, -b], [a, -b], [a, b], [-a, b]]) / 2
        else:
            r.fail(where, "give polygon, or at with diameter (round) or size (rectangular)")
        if not PolyPath(v).contains_points(hv, radius=-GEOM_TOL).all():
            r.fail(where, "is not inside the outline; move it or make it smaller")
        holes.append(hv)
    return Outline(v, holes, rect and not holes)


def _plate(r, b):
    if "thickness" in b and "stackup" in b:
        r.fail("board.thickness", "give either thickness with material, or stackup (its layers set the thickness)")
    if "stackup" in b:
        layers = []
        for i, L in enumerate(b["stackup"]):
            where = f"board.stackup[{i}]"
            r.table(L, where, ["thickness", "material", "fill", "filler"], required=["thickness", "material"])
            mats = {}
            for key in ("material", "filler"):
                name = L.get(key, "FR4")
                if isinstance(name, dict):
                    mats[key] = _material(r, name, f"{where}.{key}")
                elif name in MATERIALS:
                    mats[key] = Material(*MATERIALS[name])
                else:
                    r.fail(f"{where}.{key}", f"unknown material '{name}'; use one of {', '.join(MATERIALS)} "
                                             "or a table { E = ..., nu = ..., rho = ... }")
            fill = L.get("fill", 1.0)
            if isinstance(fill, bool) or not isinstance(fill, (int, float)) or not 0 <= fill <= 1:
                r.fail(f"{where}.fill", f"must be a number from 0 to 1, got {fill!r}")
            layers.append(Layer(r.q(L["thickness"], "mm", f"{where}.thickness", positive=True), mats["material"],
                                float(fill), mats["filler"]))
        if not layers:
            r.fail("board.stackup", "is empty; list the layers bottom to top")
        return LaminateProperty(tuple(layers)), None
    if "thickness" not in b:
        r.fail("board.thickness", "missing; add thickness = \"1.6 mm\" (or a stackup)")
    if "material" not in b:
        r.fail("board.material", "missing; add material = { E = \"26 GPa\", nu = 0.3, rho = \"2640 kg/m^3\" }")
    t = r.q(b["thickness"], "mm", "board.thickness", positive=True)
    m = _material(r, b["material"], "board.material")
    from ..fe import ShellProperty

    return ShellProperty(m.E, m.nu, m.rho, t), m


def _material(r, m, where) -> Material:
    r.table(m, where, ["E", "nu", "rho"], required=["E", "nu", "rho"])
    return Material(r.q(m["E"], "Pa", f"{where}.E", positive=True), r.number(m["nu"], f"{where}.nu", -1.0, 0.5),
                    r.q(m["rho"], "kg/m^3", f"{where}.rho", positive=True))


def _component(r, c, where, board: Board) -> Component:
    r.table(c, where, ["ref", "package", "at", "rotation", "model", "thickness", "size", "height", "mass", "E",
                       "rho"], required=["ref", "at"])
    ref = str(c["ref"])
    if board.component(ref) is not None:
        r.fail(f"{where}.ref", f"'{ref}' is used by another part; references must be unique")
    if "." in ref:
        r.fail(f"{where}.ref", f"'{ref}' contains '.', which parameter targets use as a separator; rename it")
    pkg: Package | None = None
    if "package" in c:
        try:
            pkg = find_package(str(c["package"]), board.path.parent)
        except LibraryError as exc:
            r.fail(f"{where}.package", str(exc))
        if pkg is None:
            names = available(board.path.parent)
            close = difflib.get_close_matches(str(c["package"]), names, n=1)
            hint = f"did you mean '{close[0]}'?" if close else f"known: {', '.join(names)}"
            r.fail(f"{where}.package", f"unknown package '{c['package']}' ({hint}); or give size and mass "
                                       "instead of package")
    for key in ("size", "mass"):
        if pkg is None and key not in c and not (key == "mass" and "rho" in c):
            r.fail(f"{where}.{key}", f"missing: a part without a package needs size and mass; add {key} = ...")
    if "rho" in c and "mass" in c:
        r.fail(f"{where}.rho", "give mass or rho, not both (a region density sets the part's mass)")
    if "size" in c:
        if not (isinstance(c["size"], list) and len(c["size"]) == 2):
            r.fail(f"{where}.size", "must be two lengths, e.g. [\"40 mm\", \"40 mm\"]")
        size = tuple(r.q(s, "mm", f"{where}.size[{i}]", positive=True) for i, s in enumerate(c["size"]))
    else:
        size = pkg.size
    mass = r.q(c["mass"], "g", f"{where}.mass", positive=True) if "mass" in c else (pkg.mass if pkg else 0.0)
    height = r.q(c["height"], "mm", f"{where}.height", positive=True) if "height" in c else (
        pkg.height if pkg else 0.0)
    model = c.get("model", pkg.default_model if pkg else "lumped")
    if model not in MODELS:
        close = difflib.get_close_matches(str(model), MODELS, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        r.fail(f"{where}.model", f"unknown part model '{model}'{hint}; use one of {', '.join(MODELS)}")
    thickness = None
    if model == "equivalent_thickness":
        if "thickness" in c:
            thickness = r.q(c["thickness"], "mm", f"{where}.thickness", positive=True)
        elif pkg is not None:
            thickness = pkg.equivalent_thickness
        else:
            r.fail(f"{where}.thickness", "missing: the equivalent_thickness model needs thickness = \"3.5 mm\" "
                                         "(or a package that gives one)")
    elif "thickness" in c:
        r.fail(f"{where}.thickness", f"only the equivalent_thickness model uses a thickness (model is '{model}')")
    E = r.q(c["E"], "Pa", f"{where}.E", positive=True) if "E" in c else None
    rho = r.q(c["rho"], "kg/m^3", f"{where}.rho", positive=True) if "rho" in c else None
    if E is not None and model != "smeared_local":
        r.fail(f"{where}.E", f"only the smeared_local model uses a region E (model is '{model}')")
    if rho is not None and model not in ("smeared_local", "equivalent_thickness"):
        r.fail(f"{where}.rho", f"only smeared_local and equivalent_thickness use a region rho (model is '{model}')")
    if E is not None and board.isotropic is None:
        r.fail(f"{where}.E", "a region E needs a board given by material, not by stackup")
    if rho is not None:  # the region density sets the part's mass (board + part = rho t S)
        t_region = thickness if model == "equivalent_thickness" else board.plate.t
        mass = (rho * t_region - board.plate.mass_per_area()) * size[0] * size[1]
        if mass < 0:
            r.fail(f"{where}.rho", f"region density {c['rho']!r} carries less mass than the bare board it "
                                   "replaces; raise it or use mass = ...")
    comp = Component(ref, r.point(c["at"], f"{where}.at"),
                     r.q(c.get("rotation", "0 deg"), "deg", f"{where}.rotation"), size, height, mass, model,
                     thickness, E, rho, pkg.name if pkg else None)
    if not board.outline.contains(comp.corners()).all() or not board.outline.contains(comp.at)[0]:
        r.fail(f"{where}.at", f"part {ref} ({size[0] * 1e3:g} x {size[1] * 1e3:g} mm at "
                              f"{comp.at[0] * 1e3:g}, {comp.at[1] * 1e3:g} mm) does not lie on the board; move it "
                              "so its whole footprint is inside the outline")
    for h in board.outline.holes:
        if _polys_overlap(comp.corners(), h):
            r.fail(f"{where}.at", f"part {ref} overlaps a hole in the board; move it")
    return comp


def _polys_overlap(p, q) -> bool:
    """Convex polygons overlap with positive area (separating-axis test, touching allowed)."""
    for poly in (p, q):
        e = np.roll(poly, -1, axis=0) - poly
        normals = np.c_[-e[:, 1], e[:, 0]]
        for n in normals:
            a, b = p @ n, q @ n
            scale = np.linalg.norm(n)
            if a.max() <= b.min() + GEOM_TOL * scale or b.max() <= a.min() + GEOM_TOL * scale:
                return False
    return True


def _check_overlaps(r, board):
    cs = board.components
    for i in range(len(cs)):
        for j in range(i):
            if _polys_overlap(cs[i].corners(), cs[j].corners()):
                r.fail(f"components[{i}].at", f"part {cs[i].ref} overlaps part {cs[j].ref}; move one of them "
                                              "(footprints may touch but not overlap)")


def _edge(r, text, where, outline):
    s = str(text).replace(" ", "")
    if len(s) < 3 or s[0] not in "xy" or s[1] != "=":
        r.fail(where, f"'{text}' is not an edge; write e.g. \"x=0\" or \"y=178 mm\"")
    axis = "xy".index(s[0])
    val = s[2:]
    value = 0.0 if val in ("0", "0.0") else r.q(text.split("=", 1)[1].strip(), "mm", where)
    ext = outline.edge_extent(axis, value)
    if ext is None:
        lo, hi = outline.bbox
        r.fail(where, f"'{text}' is not an edge of the outline (the board spans x = 0..{hi[0] * 1e3:g} mm, "
                      f"y = 0..{hi[1] * 1e3:g} mm); use a line the outline runs along")
    return axis, value


def _circle(centre, diameter, n=12) -> np.ndarray:
    ang = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.asarray(centre) + 0.5 * diameter * np.c_[np.cos(ang), np.sin(ang)]


def _point_on_board(r, board, f, where, what: str):
    """A fixture's ``at`` point, required and on the board."""
    if "at" not in f:
        r.fail(f"{where}.at", f"missing; a {what} needs at = [\"x mm\", \"y mm\"]")
    at = r.point(f["at"], f"{where}.at")
    if not board.outline.contains(at)[0]:
        r.fail(f"{where}.at", f"{f['at']} is not on the board; move the {what} inside the outline")
    return at


def _fixture(r, f, where, board, i) -> Fixture:
    r.table(f, where, ["name", "type", "edge", "width", "k_rot", "at", "k", "diameter", "from", "to"],
            required=["type"])
    typ = f["type"]
    if typ not in FIXTURE_TYPES:
        close = difflib.get_close_matches(str(typ), FIXTURE_TYPES, n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        r.fail(f"{where}.type", f"unknown fixture type '{typ}'{hint}; use one of {', '.join(FIXTURE_TYPES)}")
    name = str(f.get("name", f"{typ}{i + 1}"))
    if board.fixture(name) is not None:
        r.fail(f"{where}.name", f"'{name}' is used by another fixture; names must be unique")
    fx = Fixture(name, typ)
    if typ in ("clamped_edge", "hinged_edge", "wedge_lock"):
        if "edge" not in f:
            r.fail(f"{where}.edge", "missing; add edge = \"x=0\" (or \"y=178 mm\", ...)")
        fx.edge = _edge(r, f["edge"], f"{where}.edge", board.outline)
        fx.width = r.q(f["width"], "mm", f"{where}.width", nonneg=True) if "width" in f else 0.0
        if typ == "wedge_lock":
            if "k_rot" not in f:
                r.fail(f"{where}.k_rot", "missing; add k_rot = \"1e4 N*m/rad/m\" (or \"clamped\" / \"hinged\")")
            k = f["k_rot"]
            fx.k_rot = k if k in ("clamped", "hinged") else r.q(k, "N*m/rad/m", f"{where}.k_rot", nonneg=True)
    elif typ == "standoff":
        fx.at = _point_on_board(r, board, f, where, "standoff")
        k = f.get("k", "rigid")
        fx.k = "rigid" if k == "rigid" else r.q(k, "N/m", f"{where}.k", positive=True)
        fx.diameter = r.q(f.get("diameter", "6 mm"), "mm", f"{where}.diameter", positive=True)
        if not board.outline.contains(_circle(fx.at, fx.diameter)).all():
            r.fail(f"{where}.diameter", "the standoff's pad reaches off the board; move it or make it smaller")
    elif typ == "point_spring":
        fx.at = _point_on_board(r, board, f, where, "point spring")
        if "k" not in f:
            r.fail(f"{where}.k", "missing; add k = \"1e5 N/m\" (stiffness to ground in z)")
        fx.k = r.q(f["k"], "N/m", f"{where}.k", positive=True)
    elif typ == "edge_spring":
        fx.segment = _segment(r, f, where, board)
        if "k_rot" not in f:
            r.fail(f"{where}.k_rot", "missing; add k_rot = \"1e3 N*m/rad/m\" (rotation about the segment)")
        fx.k_rot = r.q(f["k_rot"], "N*m/rad/m", f"{where}.k_rot", positive=True)
    uses = {"free": (), "clamped_edge": ("edge", "width"), "hinged_edge": ("edge", "width"),
            "wedge_lock": ("edge", "width", "k_rot"), "standoff": ("at", "k", "diameter"),
            "point_spring": ("at", "k"), "edge_spring": ("from", "to", "k_rot")}[typ]
    for key in ("edge", "width", "k_rot", "at", "k", "diameter", "from", "to"):
        if key in f and key not in uses:
            r.fail(f"{where}.{key}", f"a {typ} fixture has no {key}; remove it")
    return fx


def _mass(r, m, where, board, default_name) -> PointMass:
    """A point mass; ``inertia`` J is its rotary inertia about the x and y axes (Ixx = Iyy = J,
    Izz = 0), so mass = "0 g" with an inertia > 0 declares a rotary inertia alone."""
    r.table(m, where, ["name", "at", "mass", "inertia"], required=["at", "mass"])
    pm = PointMass(str(m.get("name", default_name)), r.point(m["at"], f"{where}.at"),
                   r.q(m["mass"], "g", f"{where}.mass", nonneg=True),
                   r.q(m.get("inertia", "0 kg*m^2"), "kg*m^2", f"{where}.inertia", nonneg=True))
    if not pm.mass > 0 and not pm.inertia > 0:
        r.fail(f"{where}.mass", f"must be positive, got {m['mass']!r} (a zero mass needs an inertia > 0)")
    if not board.outline.contains(pm.at)[0]:
        r.fail(f"{where}.at", f"{m['at']} is not on the board; move the mass inside the outline")
    return pm


def _parameter(r, p, where, board) -> ParameterSpec:
    r.table(p, where, ["name", "target", "bounds"], required=["name", "target", "bounds"])
    targets = p["target"] if isinstance(p["target"], list) else [p["target"]]
    values, units = [], []
    for t in targets:
        q = board.quantity(str(t))
        if q is None:
            r.fail(f"{where}.target", f"'{t}' is not a quantity of this board; use e.g. components.<ref>.thickness "
                                      "(equivalent_thickness parts), components.<ref>.mass, components.<ref>.E/rho "
                                      "(smeared_local parts), board.E, board.rho, board.thickness, board.transverse_shear, "
                                      "fixtures.<name>.k_rot (wedge_lock with a stiffness), fixtures.<name>.k "
                                      "(standoff or point_spring), fixtures.<name>.k_rot (edge_spring), masses.<name>.mass, "
                                      "line_masses.<name>.mass, stiffeners.<name>.EI, "
                                      "regions.<name>.stiffness_factor")
        values.append(q[0])
        units.append(q[1])
    if len(set(units)) > 1:
        r.fail(f"{where}.target", f"targets {targets} have different units ({', '.join(units)}); one parameter "
                                  "value must fit them all")
    if not (isinstance(p["bounds"], list) and len(p["bounds"]) == 2):
        r.fail(f"{where}.bounds", f"must be [lower, upper], e.g. [\"1 {units[0]}\", \"10 {units[0]}\"]")
    lo, hi = (r.q(v, units[0], f"{where}.bounds[{k}]") for k, v in enumerate(p["bounds"]))
    if not lo < hi:
        r.fail(f"{where}.bounds", f"lower bound {p['bounds'][0]!r} is not below the upper {p['bounds'][1]!r}; "
                                  "swap them")
    if not np.allclose(values, values[0], rtol=1e-12):
        r.fail(f"{where}.target", f"the targets start from different values {values}; a shared parameter needs "
                                  "equal starting values")
    if not lo <= values[0] <= hi:
        r.fail(f"{where}.bounds", f"the current value {values[0]:g} (SI) lies outside [{lo:g}, {hi:g}]; widen the "
                                  "bounds or change the board")
    return ParameterSpec(str(p["name"]), [str(t) for t in targets], (lo, hi), units[0])


# ----------------------------------------------------------------------------- effect entries
def _name(r, e, where, prefix, i):
    name = str(e.get("name", f"{prefix}{i + 1}"))
    if "." in name:
        r.fail(f"{where}.name", f"'{name}' contains '.', which parameter targets use as a separator; rename it")
    return name


def _index(where):
    return int(where.rsplit("[", 1)[1].rstrip("]"))


def _on_board(outline, p0, p1) -> bool:
    """The straight segment p0 -> p1 lies on the board (sampled every 0.1 mm at most)."""
    p0, p1 = np.asarray(p0), np.asarray(p1)
    n = max(51, int(np.linalg.norm(p1 - p0) / 1e-4) + 1)
    s = np.linspace(0.0, 1.0, n)[:, None]
    return bool(outline.contains(p0 + s * (p1 - p0)).all())


def _segment(r, e, where, board):
    """((x0, y0), (x1, y1)) [m] from ``from`` and ``to``, on the board and long enough."""
    for key in ("from", "to"):
        if key not in e:
            r.fail(f"{where}.{key}", f"missing; add {key} = [\"x mm\", \"y mm\"] (the segment's ends)")
    p0, p1 = r.point(e["from"], f"{where}.from"), r.point(e["to"], f"{where}.to")
    L = math.dist(p0, p1)
    if L < MIN_SEGMENT:
        r.fail(f"{where}.to", f"the segment is too short ({L * 1e3:g} mm); its ends must be at least "
                              f"{MIN_SEGMENT * 1e3:g} mm apart")
    if not _on_board(board.outline, p0, p1):
        r.fail(f"{where}.to", f"the segment {e['from']} -> {e['to']} leaves the board; keep it inside the outline")
    return p0, p1


def _on_line(seg, a, b, tol=GEOM_TOL) -> bool:
    """Both ends of ``seg`` lie on the straight piece a -> b."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = b - a
    L = float(np.linalg.norm(d))
    for p in seg:
        rel = np.asarray(p) - a
        if abs(rel[0] * d[1] - rel[1] * d[0]) / L > tol or not -tol <= rel @ d / L <= L + tol:
            return False
    return True


def _check_edge_springs(r, board):
    """An edge spring's segment lies on one straight piece of the outline (or a hole's) or on the
    support line of an edge fixture."""
    pieces = []
    for ring in [board.outline.vertices, *board.outline.holes]:
        pieces += list(zip(ring, np.roll(ring, -1, axis=0)))
    from ..fixtures.supports import support_line

    for f in board.fixtures:
        if f.edge is not None:
            axis, v, lo, hi = support_line(board.outline, f)
            a, b = np.zeros(2), np.zeros(2)
            a[axis] = b[axis] = v
            a[1 - axis], b[1 - axis] = lo, hi
            pieces.append((a, b))
    for i, f in enumerate(board.fixtures):
        if f.type == "edge_spring" and not any(_on_line(f.segment, a, b) for a, b in pieces):
            (x0, y0), (x1, y1) = f.segment
            r.fail(f"fixtures[{i}].from", f"the segment ({x0 * 1e3:g}, {y0 * 1e3:g}) -> ({x1 * 1e3:g}, "
                                          f"{y1 * 1e3:g}) mm does not lie on the board outline or on an edge "
                                          "fixture's support line; move its ends onto one straight edge")


def _line_mass(r, e, where, board) -> LineMass:
    r.table(e, where, ["name", "from", "to", "mass"], required=["from", "to", "mass"])
    name = _name(r, e, where, "line_mass", _index(where))
    return LineMass(name, _segment(r, e, where, board), r.q(e["mass"], "g", f"{where}.mass", positive=True))


def _stiffener(r, e, where, board) -> Stiffener:
    r.table(e, where, ["name", "path", "EI", "section"], required=["path", "EI"])
    name = _name(r, e, where, "stiffener", _index(where))
    pts = e["path"]
    if not isinstance(pts, list) or len(pts) < 2:
        r.fail(f"{where}.path", "needs at least two points [[\"x mm\", \"y mm\"], ...]")
    path = tuple(r.point(p, f"{where}.path[{k}]") for k, p in enumerate(pts))
    for k, (p0, p1) in enumerate(zip(path[:-1], path[1:])):
        if math.dist(p0, p1) < MIN_SEGMENT:
            r.fail(f"{where}.path[{k + 1}]", f"is {math.dist(p0, p1) * 1e3:g} mm from the point before; pieces must "
                                             f"be at least {MIN_SEGMENT * 1e3:g} mm long")
        if not _on_board(board.outline, p0, p1):
            r.fail(f"{where}.path[{k + 1}]", f"the piece {pts[k]} -> {pts[k + 1]} leaves the board; keep the "
                                             "stiffener inside the outline")
    sec = RibSection()
    if "section" in e:
        s = r.table(e["section"], f"{where}.section", ["E", "nu", "rho", "height"])
        sec = RibSection(
            r.q(s["E"], "Pa", f"{where}.section.E", positive=True) if "E" in s else sec.E,
            r.number(s["nu"], f"{where}.section.nu", -1.0, 0.5) if "nu" in s else sec.nu,
            r.q(s["rho"], "kg/m^3", f"{where}.section.rho", positive=True) if "rho" in s else sec.rho,
            r.q(s["height"], "mm", f"{where}.section.height", positive=True) if "height" in s else sec.h)
    return Stiffener(name, path, r.q(e["EI"], "N*m^2", f"{where}.EI", positive=True), sec)


def _region(r, e, where, board) -> Region:
    r.table(e, where, ["name", "polygon", "rect", "stiffness_factor"], required=["stiffness_factor"])
    name = _name(r, e, where, "region", _index(where))
    if ("polygon" in e) == ("rect" in e):
        r.fail(where, "give polygon = [[\"x mm\", \"y mm\"], ...] or rect = [x0, y0, x1, y1] (one of them)")
    if "rect" in e:
        if not (isinstance(e["rect"], list) and len(e["rect"]) == 4):
            r.fail(f"{where}.rect", "must be [\"x0 mm\", \"y0 mm\", \"x1 mm\", \"y1 mm\"]")
        x0, y0, x1, y1 = (r.q(v, "mm", f"{where}.rect[{k}]") for k, v in enumerate(e["rect"]))
        (x0, x1), (y0, y1) = sorted((x0, x1)), sorted((y0, y1))
        if x1 - x0 < MIN_SEGMENT or y1 - y0 < MIN_SEGMENT:
            r.fail(f"{where}.rect", "has no area; give two opposite corners")
        poly = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    else:
        pts = e["polygon"]
        if not isinstance(pts, list) or len(pts) < 3:
            r.fail(f"{where}.polygon", "needs at least three points [[\"x mm\", \"y mm\"], ...]")
        poly = np.array([r.point(p, f"{where}.polygon[{k}]") for k, p in enumerate(pts)])
    x, y = poly[:, 0], poly[:, 1]
    if abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) < MIN_SEGMENT**2:
        r.fail(f"{where}.polygon", "has no area; give its corners in order")
    if not all(_on_board(board.outline, a, b) for a, b in zip(poly, np.roll(poly, -1, axis=0))):
        r.fail(f"{where}", "the region reaches off the board (or over a hole); keep it inside the outline")
    factor = r.number(e["stiffness_factor"], f"{where}.stiffness_factor")
    if not factor > 0:
        r.fail(f"{where}.stiffness_factor", f"must be > 0 (1 leaves the stiffness unchanged), got {factor:g}")
    return Region(name, poly, factor)
