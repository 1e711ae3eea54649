"""Board description -> FE model with named quantities and bounded parameters
(:class:`pcbdyn.fe.parametric.ParametricModel`: each element set is a function of named quantities
such as ``board.E``, ``components.U1.thickness``, ``fixtures.left_guide.k_rot``,
``masses.transducer.mass``; a parameter re-makes only the sets that depend on its quantities).

Element sets: ``board`` (bare board), ``components.<ref>`` (the elements under a part),
``components.<ref>.mass`` (lumped part), ``fixtures.<name>`` (wedge-lock springs, standoff
springs, point and edge springs), ``masses.<name>`` and ``configurations.<config>.<name>`` (point
masses), ``line_masses.<name>.<k>`` (one lumped share per node), ``stiffeners.<name>`` (offset
beams) and ``regions.<name>.<set>`` (the shells of ``<set>`` inside a region, stiffness scaled).
Triangles, where the mesher leaves any, go to a companion set named ``<set>.tri3``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import targets
from ..components import models as parts
from ..domain import check_mesh_size as check_size
from ..domain import configuration_of
from ..fe import Model
from ..fe.model import SHELL_TYPES
from ..fe.parametric import ParametricModel, SetMaker
from ..fixtures import supports
from . import effects
from .entries import BoardError
from .mesh import BoardMesh, mesh_board


@dataclass
class BoardModel(ParametricModel):
    """The FE model of one configuration of a board (a :class:`ParametricModel` with the board, its
    mesh and the configuration's name)."""

    board: object = None  # the Board
    mesh: BoardMesh | None = None
    configuration: str | None = None

    def with_shear_factor(self, factor: float) -> "BoardModel":
        """A copy whose shells' transverse shear stiffness is ``factor`` times the declared (a large
        factor: the Kirchhoff plate)."""
        return self.with_quantities({parts.SHEAR_KEY: self.quantities[parts.SHEAR_KEY] * factor})

    def layout_hints(self) -> tuple:
        """(suspects {name: node}, footprints {name: polygon [m]}, plate thickness [m]) for a diagnosis:
        measurement points and declared masses are prime suspects, part footprints candidate regions."""
        suspects = {n: v for n, v in self.point_nodes.items() if n.startswith(("points.", "masses."))}
        footprints = {targets.entry("components", c.ref): c.corners() for c in self.board.components}
        return suspects, footprints, self.board.thickness


def check_mesh_size(board, size: float) -> None:
    """A BoardError for a mesh size far off the board (:func:`pcbdyn.domain.check_mesh_size`)."""
    lo, hi = board.outline.bbox
    check_size(f"{board.path.name}: board.mesh_size", float(np.min(hi - lo)), board.outline.area(), size, BoardError)


def mesh_points(board, config, shared: bool = False) -> list:
    """Named points that must be mesh nodes; ``shared``: those of every configuration, so that all
    configurations mesh alike."""
    pts = [(targets.entry("masses", m.name), m.at) for m in board.masses]
    for c in (board.configurations if shared else [config] if config is not None else []):
        pts += [(targets.member(targets.entry("configurations", c.name), m.name), m.at) for m in c.masses]
    pts += [(f"points.{i + 1}", p) for i, p in enumerate(board.points)]
    pts += [(targets.entry("fixtures", f.name), f.at) for f in board.fixtures if f.type == "point_spring"]
    return pts


def mesh_lines(board) -> list:
    """Polylines element edges must follow: edge springs, line masses, stiffener paths and the
    board's guides (:meth:`.board.Board.following`)."""
    lines = [np.array(f.segment) for f in board.fixtures if f.type == "edge_spring"]
    lines += [np.array(e.segment) for e in board.line_masses]
    lines += [np.array(e.path) for e in board.stiffeners]
    return lines + list(board.guides)


def build_model(board, config: str | None = None, mesh_size: float | None = None,
                shared_mesh: bool = False, housed: bool = False) -> BoardModel:
    """The FE model of ``board`` in configuration ``config`` (None: the base configuration).
    ``shared_mesh``: every configuration's points are nodes, so that the models of all
    configurations share one mesh node for node (diagnosis places effects by node). ``housed``: the
    edge fixtures and standoffs hold nothing (a housing holds the card, :mod:`pcbdyn.box.system`); a
    standoff still has its centre node, tied to its pad."""
    cfg = configuration_of(board, config, BoardError)
    check_mesh_size(board, mesh_size or board.mesh_size)
    named = mesh_points(board, cfg, shared_mesh)
    regions = [(targets.entry("components", c.ref), c.corners()) for c in board.components] if board.smear == "none" else []
    strips = [s for f in board.fixtures if f.edge is not None
              if (s := supports.strip_polygon(board.outline, f)) is not None]
    strips += [supports.pad_polygon(f) for f in board.fixtures if f.type == "standoff"]
    strips += [e.polygon for e in board.regions]
    try:
        mesh = mesh_board(board.outline, regions, [p for _, p in named], mesh_size or board.mesh_size, strips,
                          mesh_lines(board))
    except RuntimeError as exc:
        raise BoardError(f"{board.path.name}: board.mesh_size: meshing failed ({exc})") from None
    point_nodes = {name: int(n) for (name, _), n in zip(named, mesh.point_nodes)}

    q = {parts.SHEAR_KEY: board.transverse_shear}
    if board.isotropic is not None:
        q.update({"board.E": board.isotropic.E, "board.rho": board.isotropic.rho, "board.thickness": board.plate.t})
    q.update(parts.initial_quantities(board))
    makers: dict = {}

    def add(name, etype, conn, deps, make):
        makers[name] = SetMaker(etype, np.asarray(conn, dtype=np.int64), tuple(deps), make)

    def add_shells(name, cells, deps, make):
        for etype, conn in cells.items():
            add(name if etype == "quad4" else targets.member(name, etype), etype, conn, deps, make)

    nsm = parts.global_nsm(board)
    add_shells("board", mesh.cells.get("board", {}), parts.board_keys(board),
               lambda q: parts.base_property(board, q, nsm))
    for c in board.components if board.smear == "none" else []:
        name = targets.entry("components", c.ref)
        add_shells(name, mesh.cells[name], parts.region_keys(board, c),
                   lambda q, c=c: parts.region_property(board, c, q))
    model = Model(mesh.nodes.copy())
    for c in board.components if board.smear == "none" else []:
        if c.model == "lumped":
            name = targets.entry("components", c.ref)
            centre = int(model.add_nodes([[c.at[0], c.at[1], 0.0]])[0])
            footprint = np.unique(np.concatenate([conn.ravel() for conn in mesh.cells[name].values()]))
            parts.follow_footprint(model, centre, footprint)
            point_nodes[name] = centre
            add(targets.member(name, "mass"), "mass", [[centre]], (targets.target("components", c.ref, "mass"),), lambda q, c=c: parts.lumped_mass(c, q))
    supported = False
    for f in board.fixtures:
        if f.edge is not None:
            for mk in ([] if housed else supports.apply_edge(model, mesh, board.outline, f, q)):
                add(*mk)
            supported = True
        elif f.type == "standoff":
            centre = int(model.add_nodes([[f.at[0], f.at[1], 0.0]])[0])
            point_nodes[targets.entry("fixtures", f.name)] = centre
            for mk in supports.apply_standoff(model, centre, f, q, grounded=not housed):
                add(*mk)
            supported = True
        elif f.type in ("point_spring", "edge_spring"):  # springs to ground that leave rigid motions free
            for mk in effects.apply_fixture(board, mesh, f, point_nodes, q):
                add(*mk)
    masses = [(targets.entry("masses", m.name), m) for m in board.masses]
    masses += [(targets.member(targets.entry("configurations", cfg.name), m.name), m) for m in (cfg.masses if cfg else [])]
    for name, m in masses:
        node = point_nodes[name]
        shells = [(t, mesh.all_cells(t)) for t in SHELL_TYPES]
        add(*supports.point_mass(name, node, m, q, supports.mass_footprint(mesh.nodes, shells, node, m.mass, m.inertia)))
    for mk in effects.effect_sets(board, mesh, q, makers):
        add(*mk)
    model.free = not supported
    model.node_groups.update({name: np.array([n]) for name, n in point_nodes.items()})
    bm = BoardModel.assemble_from(model, q, makers, point_nodes=point_nodes, board=board, mesh=mesh,
                                  configuration=config)
    bm.bind(board.parameters)
    return bm
