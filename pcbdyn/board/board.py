"""A board: its validated description and the domain-model interface (:mod:`pcbdyn.domain`) that the
bridge to updating and diagnosis uses: the quantities parameter targets address, the FE model of a
configuration, measurement points on the board, and the updated board.toml."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import targets
from ..atomic import write_checked
from ..domain import Configured
from ..inputs import MAX_NAME, Reader, read_toml
from .entries import Analysis, BoardError, Component, Configuration, Outline
from .laminate import Material
from .enrich import enriched_text
from .model import BoardModel, build_model
from .outlines import board_outlines
from .spec import read_outline, read_plate
from .spec_effects import read_line_mass, read_region, read_stiffener
from .spec_fixtures import check_edge_springs, read_fixture, read_mass
from .spec_parts import check_overlaps, read_component

#: the collections of board.toml that parameter targets address
COLLECTIONS = ("board", "components", "fixtures", "masses", "line_masses", "stiffeners", "regions")


@dataclass
class Board(Configured):
    """A printed circuit board as board.toml describes it (SI units, the board frame): outline, plate
    (isotropic or stack-up), parts, fixtures, masses, effect entries, test configurations, parameters
    and analysis settings; :func:`load_board` reads and validates it, :meth:`build` makes its FE model."""

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
    parameters: list  # pcbdyn.targets.ParameterSpec
    analysis: Analysis
    points: list  # measurement points (x, y) [m] to put nodes on
    line_masses: list = field(default_factory=list)
    stiffeners: list = field(default_factory=list)
    regions: list = field(default_factory=list)
    transverse_shear: float = 1.0  # factor on every shell's transverse shear stiffness
    guides: list = field(default_factory=list)  # lines (m, 2) [m] element edges follow with nothing on them

    @property
    def thickness(self) -> float:
        return self.plate.t

    def component(self, ref):
        return next((c for c in self.components if c.ref == ref), None)

    def fixture(self, name):
        return next((f for f in self.fixtures if f.name == name), None)

    def point_mass(self, name):
        return next((m for m in self.masses if m.name == name), None)

    def entry(self, kind, name):
        """The ``line_masses``, ``stiffeners`` or ``regions`` entry called ``name`` (or None)."""
        return next((e for e in getattr(self, kind) if e.name == name), None)

    def quantity(self, target: str) -> float | None:
        """The current value [SI] of a parameter target such as ``components.U1.thickness``; None when
        this board has no such quantity (e.g. a thickness of a lumped part)."""
        try:
            t = targets.parse(target, COLLECTIONS)
        except targets.TargetError:
            return None
        kind, name, attr = t.collection, t.name, t.attribute
        if kind == "board":
            if attr == "transverse_shear":
                return self.transverse_shear
            if self.isotropic is None:
                return None
            return {"E": self.isotropic.E, "rho": self.isotropic.rho, "thickness": self.plate.t}[attr]
        if kind == "components" and (c := self.component(name)) is not None and self.smear == "none":
            return {"thickness": c.thickness if c.model == "equivalent_thickness" else None, "mass": c.mass,
                    "E": (c.E if c.E is not None else self.isotropic.E)
                    if c.model == "smeared_local" and self.isotropic is not None else None,
                    "rho": smeared_density(self, c) if c.model == "smeared_local" else None}[attr]
        if kind == "fixtures" and (f := self.fixture(name)) is not None:
            if attr == "k_rot" and f.type in ("wedge_lock", "edge_spring") and isinstance(f.k_rot, float):
                return f.k_rot
            if attr == "k" and f.type in ("standoff", "point_spring") and isinstance(f.k, float):
                return f.k
            return None
        if kind == "masses" and (m := self.point_mass(name)) is not None:
            return {"mass": m.mass, "inertia": m.inertia}[attr]
        if kind in ("line_masses", "stiffeners", "regions") and (e := self.entry(kind, name)) is not None:
            return getattr(e, attr)
        return None

    # -------------------------------------------------------------------- domain-model interface
    def build(self, config: str | None = None, mesh_size: float | None = None, shared_mesh: bool = False) -> BoardModel:
        """The FE model of configuration ``config`` as a function of the board's quantities.

        Parameters
        ----------
        config : str, optional
            A ``[[configurations]]`` name (None: the base configuration).
        mesh_size : float, optional
            Element size [m] (default: the board's ``mesh_size``).
        shared_mesh : bool
            Mesh every configuration's points, so that all configurations share one mesh.

        Returns
        -------
        BoardModel
            A :class:`pcbdyn.fe.parametric.ParametricModel`: ``model`` (the :class:`pcbdyn.fe.Model`),
            ``parameters`` (the ``[[parameters]]``), ``with_parameters({name: value})`` (a copy at
            other values, SI) and ``point_nodes``. See :func:`.model.build_model`.

        Examples
        --------
        >>> from pcbdyn.fe.modal import solve_modes
        >>> card = load_board("examples/six_part_card/board.toml").build()
        >>> sorted(card.parameters)
        ['E_board', 't_CQFP', 't_JLCC', 't_PGA']
        >>> f = solve_modes(card.model, n_modes=2).frequencies
        >>> thicker = solve_modes(card.with_parameters({"t_PGA": 4.2e-3}).model, n_modes=2).frequencies
        >>> bool(thicker[0] > f[0])
        True
        """
        return build_model(self, config, mesh_size, shared_mesh)

    def check_points(self, points, source) -> None:
        """A BoardError naming the points (``points.ids``, ``points.xyz`` [m]) of ``source`` that lie
        off the outline or in a hole, before any meshing."""
        off = ~self.outline.contains(points.xyz[:, :2], tol=1e-6)
        if off.any():
            listed = ", ".join(f"{int(i)} ({x * 1e3:g}, {y * 1e3:g} mm)"
                               for i, (x, y) in zip(points.ids[off][:10], points.xyz[off, :2][:10]))
            lo, hi = self.outline.bbox
            raise BoardError(
                f"{Path(source).name}: {int(off.sum())} point(s) lie off the board of {self.path.name} (not on the "
                f"board): {listed}"
                f"{' ...' if off.sum() > 10 else ''}. The board frame runs from ({lo[0] * 1e3:g}, {lo[1] * 1e3:g}) to "
                f"({hi[0] * 1e3:g}, {hi[1] * 1e3:g}) mm; give the points in that frame and state their unit in the "
                "header (e.g. 'x [mm]')")

    def outlines(self, config: str | None = None) -> list:
        """What a mode-shape picture outlines, as plain data (:func:`.outlines.board_outlines`)."""
        return board_outlines(self, config)

    def following(self, lines) -> "Board":
        """This board meshed so that element edges also follow ``lines`` (polylines (m, 2) [m]) with
        nothing declared on them: where a diagnosis found stiffeners (:mod:`pcbdyn.diagnosis.conforming`)."""
        return replace(self, guides=[np.asarray(line, float) for line in lines])

    def write_enriched(self, effects, dst, date: str | None = None, values: dict | None = None) -> Path:
        """``dst``: this board.toml with the effects a diagnosis found declared (:mod:`.enrich`) and the
        parameters' fitted ``values`` {name: SI} written into their targets, so that it builds the diagnosed
        model; written atomically once it loads."""
        text = self._updated_text(values or {}, "pcbdyn diagnose")
        return write_checked(dst, enriched_text(text, effects, date), load_board, BoardError)

    def write_updated(self, values: dict, dst, source: str = "pcbdyn update") -> Path:
        """``dst``: this board.toml with the parameters' ``values`` {name: SI} written into their targets
        (comments and layout kept), checked by loading it before it replaces ``dst``."""
        return write_checked(dst, self._updated_text(values, source), load_board, BoardError)

    def _updated_text(self, values: dict, source: str) -> str:
        """This board.toml's text with the parameters' ``values`` written in (itself when there are none)."""
        text = self.path.read_text(encoding="utf-8")
        if not values:
            return text
        header = f"# {self.path.name} with {', '.join(values)} updated by {source}\n"
        return header + targets.updated_text(text, targets.assignments(self.parameters, values))


def smeared_density(board: Board, c: Component) -> float:
    """Region density of a locally smeared part: the board's plus the part mass over its volume of
    board, so the region carries board + part mass (thesis 7.2.3, local smearing)."""
    t = board.plate.t
    rho_b = board.plate.mass_per_area() / t
    return rho_b + c.mass / (c.area * t)


def load_board(path) -> Board:
    """Read and validate a board.toml (the format: docs/board-toml.md).

    Parameters
    ----------
    path : str or pathlib.Path
        The board.toml; the component library and any stackup it names are found from it.

    Returns
    -------
    Board
        The board's outline, plate, parts, fixtures, effects, configurations and ``[[parameters]]``,
        in SI. A :class:`BoardError` names the file, the field and the fix of the first mistake.

    Examples
    --------
    >>> board = load_board("examples/six_part_card/board.toml")
    >>> [p.name for p in board.parameters]
    ['t_PGA', 't_JLCC', 't_CQFP', 'E_board']
    >>> board.thickness                              # SI: m
    0.0028
    """
    return parse_board(read_toml(path, BoardError)[1], Path(path))


def parse_board(data: dict, path: Path) -> Board:
    """The Board of parsed board.toml ``data`` read from ``path``; a BoardError names the first bad field."""
    r = Reader(path, BoardError)
    if "box" in data and "board" not in data:
        r.fail("top level", "describes a box ([box]); this command takes a board.toml ([board]): boxes are built, "
                            "tested, updated, localised and diagnosed by build, simulate-test, correlate, update, "
                            "localize, diagnose and study, and a box with [[cards]] is judged by vibe")
    r.table(data, "top level", ["board", "components", "fixtures", "masses", "configurations", "parameters",
                                "analysis", "points", "line_masses", "stiffeners", "regions"], required=["board"])
    b = r.table(data["board"], "board", ["name", "outline", "thickness", "material", "stackup", "mesh_size",
                                         "smear", "transverse_shear"], required=["outline"])
    outline = read_outline(r, b["outline"])
    plate, iso = read_plate(r, b)
    lo, hi = outline.bbox
    if plate.t >= float(np.min(hi - lo)):
        r.fail("board.thickness", f"{plate.t * 1e3:g} mm is as thick as the board is wide ({float(np.min(hi - lo)) * 1e3:g}"
                                  " mm); a board is a plate: check the units")
    mesh_size = r.q(b.get("mesh_size", "5 mm"), "mm", "board.mesh_size", positive=True)
    smear = r.choice(b.get("smear", "none"), "board.smear", ("none", "global"), "smearing",
                     {"global": "spread every part's mass over the board"})
    shear = r.number(b.get("transverse_shear", 1.0), "board.transverse_shear", lo=0.0)
    board = Board(
        name=r.text(b["name"], "board.name", MAX_NAME) if "name" in b else Path(path).parent.name, path=Path(path), outline=outline, plate=plate,
        isotropic=iso, mesh_size=mesh_size, smear=smear, components=[], fixtures=[], masses=[],
        configurations=[], parameters=[], analysis=Analysis(), points=[], transverse_shear=shear,
    )
    for i, c in enumerate(r.list(data, "components")):
        board.components.append(read_component(r, c, f"components[{i}]", board))
    check_overlaps(r, board)
    for i, f in enumerate(r.list(data, "fixtures")):
        board.fixtures.append(read_fixture(r, f, f"fixtures[{i}]", board, i))
    check_edge_springs(r, board)
    for i, m in enumerate(r.list(data, "masses")):
        board.masses.append(read_mass(r, m, f"masses[{i}]", board, i))
    r.unique([m.name for m in board.masses], "masses", "name")
    for key, read in (("line_masses", read_line_mass), ("stiffeners", read_stiffener), ("regions", read_region)):
        for i, e in enumerate(r.list(data, key)):
            getattr(board, key).append(read(r, e, f"{key}[{i}]", board))
        r.unique([e.name for e in getattr(board, key)], key, "name")
    for i, c in enumerate(r.list(data, "configurations")):
        where = f"configurations[{i}]"
        r.table(c, where, ["name", "masses"], required=["name"])
        name = r.name("configurations", c, i, where)
        ms = [read_mass(r, m, f"{where}.masses[{j}]", board, j) for j, m in enumerate(r.list(c, "masses", f"{where}.masses"))]
        r.unique([m.name for m in ms], f"{where}.masses", "name")
        board.configurations.append(Configuration(name, ms))
    r.unique([c.name for c in board.configurations], "configurations", "name")
    for i, p in enumerate(r.list(data, "points")):
        pt = r.point(p, f"points[{i}]")
        if not outline.contains(pt)[0]:
            r.fail(f"points[{i}]", f"{p} is not on the board; move it inside the outline")
        board.points.append(pt)
    board.analysis = r.analysis(data)
    board.parameters = targets.read_parameters(r, data, board.quantity, COLLECTIONS)
    return board
