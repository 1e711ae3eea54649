"""Board description -> FE model with named quantities and bounded parameters.

Every element set is made by a function of a dictionary of named quantities (``board.E``,
``components.U1.thickness``, ``fixtures.left_guide.k_rot``, ``masses.transducer.mass``, ...) and
records which quantities it depends on. A parameter is a named, bounded value shared by one or
more quantities; changing it re-makes only the sets that depend on them, which is also how its
dK/dp and dM/dp are formed (see :mod:`pcbdyn.board.parameters`).

Element sets: ``board`` (bare board), ``components.<ref>`` (the elements under a part),
``components.<ref>.mass`` (lumped part), ``fixtures.<name>`` (wedge-lock springs, standoff
springs, point and edge springs), ``masses.<name>`` and ``configurations.<config>.<name>`` (point
masses), ``line_masses.<name>.<k>`` (one lumped share per node), ``stiffeners.<name>`` (offset
beams) and ``regions.<name>.<set>`` (the shells of ``<set>`` inside a region, stiffness scaled).
Triangles, where the mesher leaves any, go to a companion set named ``<set>.tri3``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..components import models as parts
from ..fe import Model
from ..fixtures import supports
from . import effects
from .mesh import BoardMesh, mesh_board
from .spec import Board, BoardError


@dataclass
class SetMaker:
    etype: str
    conn: np.ndarray
    deps: tuple
    make: object  # q -> property


@dataclass
class BoardModel:
    """The FE model of one configuration of a board and how to re-make its sets."""

    board: Board
    mesh: BoardMesh
    model: Model
    quantities: dict
    makers: dict
    configuration: str | None
    point_nodes: dict = field(default_factory=dict)  # name -> node index
    parameters: dict = field(default_factory=dict)

    def sets_depending_on(self, keys) -> list:
        keys = set(keys)
        return [n for n, mk in self.makers.items() if keys & set(mk.deps)]

    def properties(self, values: dict) -> dict:
        """{set name: property} of the sets touched when the quantities ``values`` change."""
        q = {**self.quantities, **values}
        return {n: self.makers[n].make(q) for n in self.sets_depending_on(values)}

    def with_quantities(self, values: dict) -> "BoardModel":
        """A copy whose quantities are changed (the FE model shares nodes and unchanged sets)."""
        for k in values:
            if k not in self.quantities:
                raise BoardError(f"'{k}' is not a quantity of this model")
        model = Model(self.model.nodes, dict(self.model.sets), dict(self.model.node_groups), set(self.model.fixed),
                      list(self.model.mpcs), self.model.free)
        for name, prop in self.properties(values).items():
            es = model.sets[name]
            model.sets[name] = type(es)(es.name, es.etype, es.conn, prop)
        return BoardModel(self.board, self.mesh, model, {**self.quantities, **values}, self.makers,
                          self.configuration, self.point_nodes, self.parameters)

    def with_parameters(self, values: dict) -> "BoardModel":
        """A copy with parameters {name: value [SI]} set (each value goes to all its targets)."""
        q = {}
        for name, v in values.items():
            q.update(self.parameters[name].quantities(v))
        return self.with_quantities(q)

    def mass(self) -> float:
        """Total translational mass [kg] from the assembled mass matrix (u = 1 in z everywhere)."""
        from ..fe.assembly import assemble

        _, M = assemble(self.model)
        r = np.zeros(self.model.n_dof)
        r[2::6] = 1.0
        return float(r @ (M @ r))


def mesh_points(board: Board, config, shared: bool = False) -> list:
    """Named points that must be mesh nodes; ``shared``: those of every configuration, so that all
    configurations mesh alike."""
    pts = [(f"masses.{m.name}", m.at) for m in board.masses]
    for c in (board.configurations if shared else [config] if config is not None else []):
        pts += [(f"configurations.{c.name}.{m.name}", m.at) for m in c.masses]
    pts += [(f"points.{i + 1}", p) for i, p in enumerate(board.points)]
    pts += [(f"fixtures.{f.name}", f.at) for f in board.fixtures if f.type == "point_spring"]
    return pts


def mesh_lines(board: Board) -> list:
    """Polylines element edges must follow: edge springs, line masses and stiffener paths."""
    lines = [np.array(f.segment) for f in board.fixtures if f.type == "edge_spring"]
    lines += [np.array(e.segment) for e in board.line_masses]
    lines += [np.array(e.path) for e in board.stiffeners]
    return lines


def build_model(board: Board, config: str | None = None, mesh_size: float | None = None,
                shared_mesh: bool = False) -> BoardModel:
    """The FE model of ``board`` in configuration ``config`` (None: the base configuration).
    ``shared_mesh``: every configuration's points are nodes, so that the models of all
    configurations share one mesh node for node (diagnosis places effects by node)."""
    from .parameters import Parameter

    cfg = None
    if config is not None:
        cfg = board.configuration(config)
        if cfg is None:
            names = ", ".join(c.name for c in board.configurations) or "none defined"
            raise BoardError(f"{board.path.name}: configuration '{config}' does not exist (configurations: {names})")
    named = mesh_points(board, cfg, shared_mesh)
    regions = [(f"components.{c.ref}", c.corners()) for c in board.components] if board.smear == "none" else []
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

    q = {parts.SHEAR_KEY: 1.0}
    if board.isotropic is not None:
        q.update({"board.E": board.isotropic.E, "board.rho": board.isotropic.rho, "board.thickness": board.plate.t})
    q.update(parts.initial_quantities(board))
    makers: dict = {}

    def add(name, etype, conn, deps, make):
        makers[name] = SetMaker(etype, np.asarray(conn, dtype=np.int64), tuple(deps), make)

    def add_shells(name, cells, deps, make):
        for etype, conn in cells.items():
            add(name if etype == "quad4" else f"{name}.{etype}", etype, conn, deps, make)

    nsm = parts.global_nsm(board)
    add_shells("board", mesh.cells.get("board", {}), parts.board_keys(board),
               lambda q: parts.base_property(board, q, nsm))
    for c in board.components if board.smear == "none" else []:
        name = f"components.{c.ref}"
        add_shells(name, mesh.cells[name], parts.region_keys(board, c),
                   lambda q, c=c: parts.region_property(board, c, q))
    model = Model(mesh.nodes.copy())
    for c in board.components if board.smear == "none" else []:
        if c.model == "lumped":
            name = f"components.{c.ref}"
            centre = int(model.add_nodes([[c.at[0], c.at[1], 0.0]])[0])
            footprint = np.unique(np.concatenate([conn.ravel() for conn in mesh.cells[name].values()]))
            parts.follow_footprint(model, centre, footprint)
            point_nodes[name] = centre
            add(f"{name}.mass", "mass", [[centre]], (f"{name}.mass",), lambda q, c=c: parts.lumped_mass(c, q))
    supported = False
    for f in board.fixtures:
        if f.edge is not None:
            for mk in supports.apply_edge(model, mesh, board.outline, f, q):
                add(*mk)
            supported = True
        elif f.type == "standoff":
            centre = int(model.add_nodes([[f.at[0], f.at[1], 0.0]])[0])
            point_nodes[f"fixtures.{f.name}"] = centre
            for mk in supports.apply_standoff(model, centre, f, q):
                add(*mk)
            supported = True
        elif f.type in ("point_spring", "edge_spring"):  # springs to ground that leave rigid motions free
            for mk in effects.apply_fixture(board, mesh, f, point_nodes, q):
                add(*mk)
    masses = [(f"masses.{m.name}", m) for m in board.masses]
    masses += [(f"configurations.{cfg.name}.{m.name}", m) for m in (cfg.masses if cfg else [])]
    for name, m in masses:
        node = point_nodes[name]
        shells = [(t, mesh.all_cells(t)) for t in ("quad4", "tri3")]
        add(*supports.point_mass(name, node, m, q, supports.mass_footprint(mesh.nodes, shells, node, m.mass, m.inertia)))
    for mk in effects.effect_sets(board, mesh, q, makers):
        add(*mk)
    model.free = not supported
    for name, mk in makers.items():
        model.add(name, mk.etype, mk.conn, mk.make(q))
    model.node_groups.update({name: np.array([n]) for name, n in point_nodes.items()})
    bm = BoardModel(board, mesh, model, q, makers, config, point_nodes)
    bm.parameters = {p.name: Parameter.from_spec(p, bm) for p in board.parameters}
    return bm
