"""The FE model: nodes, element sets (each with one property), fixed DOFs and multi-point constraints."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .mesh import NDOF, dof_index

#: nodes per cell for each element type
NODES_PER_CELL = {"quad4": 4, "tri3": 3, "beam2": 2, "edge_spring": 2, "edge_joint": 4, "mass": 1,
                   "embedded_beam2": 8}
#: the shell element types (plates: bending and membrane), in the order sets of them are made
SHELL_TYPES = ("quad4", "tri3")


class ModelError(ValueError):
    """A model that cannot be assembled or solved, with what to change."""


@dataclass
class ElementSet:
    """Cells of one element type sharing one property.

    ``etype`` is one of quad4, tri3, beam2, spring (1 node: to ground, 2 nodes: node to node),
    edge_spring, edge_joint (springs between two coincident edges: a1, a2, b1, b2), mass,
    embedded_beam2 (a beam between points of two host shell cells: their 4 + 4 nodes). ``conn`` holds
    node indices, shape (n_cells, nodes_per_cell). ``frame``: None (the property's directions are global
    axes), or a rotation R (3, 3) whose columns are the set's own axes in global ones: its element
    matrices are formed on the nodes in those axes, with the property's directions in them, and turned
    to global DOFs (:func:`.frames.to_global`): a part described in its own frame (a card in a housing).
    """

    name: str
    etype: str
    conn: np.ndarray
    prop: object
    frame: np.ndarray | None = None

    def __post_init__(self):
        self.conn = np.atleast_2d(np.asarray(self.conn, dtype=np.int64))
        if self.etype == "spring":
            weights = getattr(self.prop, "weights", None)
            if weights is not None and self.conn.shape[1] != len(weights):
                raise ModelError(f"element set '{self.name}': a spring at a point has one weight per node of its "
                                 f"cells, got {len(weights)} weights for {self.conn.shape[1]} nodes")
            if weights is None and self.conn.shape[1] not in (1, 2):
                raise ModelError(f"element set '{self.name}': a spring cell has 1 or 2 nodes (more with weights)")
        elif self.etype == "mass":
            if self.conn.shape[1] == 2:
                raise ModelError(f"element set '{self.name}': a mass cell has 1 node or a footprint of 3 or more")
        elif self.etype in NODES_PER_CELL:
            if self.conn.shape[1] != NODES_PER_CELL[self.etype]:
                raise ModelError(
                    f"element set '{self.name}': {self.etype} cells need {NODES_PER_CELL[self.etype]} "
                    f"nodes, got {self.conn.shape[1]}"
                )
        else:
            raise ModelError(
                f"element set '{self.name}': unknown element type '{self.etype}' "
                f"(use one of {', '.join(sorted(NODES_PER_CELL) + ['spring'])})"
            )


@dataclass
class Model:
    """Nodes (n, 3) [m], element sets, named node groups, constraints.

    ``fixed``: global DOF numbers held at zero. ``mpcs``: linear constraints, each a pair
    ``(slave_dof, [(master_dof, coefficient), ...])`` meaning u_slave = sum(c * u_master);
    they are applied by elimination. ``free``: the model is meant to float (rigid-body modes
    are expected and reported, not an error).
    """

    nodes: np.ndarray
    sets: dict = field(default_factory=dict)
    node_groups: dict = field(default_factory=dict)
    fixed: set = field(default_factory=set)
    mpcs: list = field(default_factory=list)
    free: bool = False

    def __post_init__(self):
        self.nodes = np.asarray(self.nodes, dtype=float).reshape(-1, 3)

    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def n_dof(self) -> int:
        return NDOF * self.n_nodes

    def add(self, name: str, etype: str, conn, prop, frame=None) -> ElementSet:
        """Add an element set (``frame``: see :class:`ElementSet`); names are unique (a parameter
        addresses a set by name)."""
        if name in self.sets:
            raise ModelError(f"element set '{name}' already exists")
        es = ElementSet(name, etype, conn, prop, frame)
        if es.conn.size and (es.conn.min() < 0 or es.conn.max() >= self.n_nodes):
            raise ModelError(f"element set '{name}' refers to a node outside 0..{self.n_nodes - 1}")
        self.sets[name] = es
        return es

    def add_nodes(self, xyz) -> np.ndarray:
        """Append nodes and return their indices."""
        xyz = np.asarray(xyz, dtype=float).reshape(-1, 3)
        first = self.n_nodes
        self.nodes = np.vstack([self.nodes, xyz])
        return np.arange(first, first + xyz.shape[0])

    def fix(self, nodes, dofs=None) -> None:
        """Hold DOFs of nodes at zero (names from ux..rz or 0-5; default all six)."""
        self.fixed.update(int(d) for d in np.ravel(dof_index(nodes, dofs)))

    def rigid_link(self, master: int, slaves, dofs=range(6)) -> None:
        """Tie ``slaves`` to ``master`` as a rigid body: u_s = u_m + theta_m x (x_s - x_m), theta_s = theta_m.

        ``dofs`` (0-5) limits the link to some slave DOFs, e.g. (0, 1, 2) for a pinned joint.
        """
        xm = self.nodes[master]
        m = dof_index(master)
        for s in np.atleast_1d(slaves):
            d = self.nodes[int(s)] - xm
            sd = dof_index(int(s))
            rows = {
                0: [(m[0], 1.0), (m[4], d[2]), (m[5], -d[1])],
                1: [(m[1], 1.0), (m[5], d[0]), (m[3], -d[2])],
                2: [(m[2], 1.0), (m[3], d[1]), (m[4], -d[0])],
                3: [(m[3], 1.0)],
                4: [(m[4], 1.0)],
                5: [(m[5], 1.0)],
            }
            for j in dofs:
                self.constrain(sd[j], rows[j])

    def constrain(self, slave_dof: int, terms) -> None:
        """General multi-point constraint u_slave = sum(c * u_master) over ``terms`` = [(master_dof, c), ...]."""
        self.mpcs.append((int(slave_dof), [(int(m), float(c)) for m, c in terms]))

    def couple(self, dof_a: int, dof_b: int) -> None:
        """Make global DOF ``dof_b`` equal to ``dof_a``."""
        self.constrain(dof_b, [(dof_a, 1.0)])

    def copy(self) -> "Model":
        """A shallow copy whose sets, node groups, fixed DOFs and constraints can be added to or
        replaced without touching this model (the node array and the element sets themselves are
        shared: neither is changed in place). The one way a model is copied."""
        return replace(self, sets=dict(self.sets), node_groups=dict(self.node_groups), fixed=set(self.fixed),
                       mpcs=list(self.mpcs))

    def with_property(self, name: str, **changes) -> "Model":
        """A copy whose set ``name`` has its property fields changed (for re-analysis)."""
        new = self.copy()
        es = self.sets[name]
        new.sets[name] = replace(es, prop=replace(es.prop, **changes))
        return new
