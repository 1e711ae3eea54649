"""Box description -> FE model with named quantities and bounded parameters
(:class:`pcbdyn.fe.parametric.ParametricModel`, as a board's): each element set is a function of named
quantities such as ``plates.upper.E``, ``ribs.left_v1.height``, ``joints.upper_left.k_rot``,
``masses.relay.mass``, so that a parameter re-makes only the sets that depend on its quantities and
gives exact dK/dp, dM/dp.

Element sets: ``plates.<name>`` (flat shells in 3-D, 6 DOF per node; triangles in ``plates.<name>.tri3``),
``ribs.<name>`` (eccentric beams on the rib line, or a shell strip: :mod:`.ribs`), ``joints.<name>``
(rotational springs per unit length about an edge two plates share: the second plate gets its own copy
of the edge's nodes, tied to the first's in translation and in the rotations across the edge; nodes
where the edge meets another shared or supported edge of that plate stay rigid), ``masses.<name>`` and
``configurations.<config>.<name>`` (point masses). Edges two plates share are rigid unless a joint
names them (one mesh, shared nodes). Supports hold a plate's edge: clamped (every DOF) or hinged (the
rotation about the edge free).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .. import targets
from ..domain import check_mesh_size, configuration_of
from ..fe import EdgeSpringProperty, Model, OrthotropicShellProperty, ShellProperty, dof_index
from ..fe.assembly import assemble
from ..fe.parametric import ParametricModel, SetMaker
from ..fixtures import supports
from .entries import BoxError
from .geometry import segment_gap
from .mesh import BoxMesh, mesh_box
from .ribs import add_strips, hold_ends, rib_section

#: the quantity that multiplies every shell's transverse shear stiffness (1: 5/6 G t)
SHEAR_KEY = "box.transverse_shear"


@dataclass
class BoxModel(ParametricModel):
    """The FE model of one configuration of a box (a :class:`ParametricModel` with the box, its mesh, the
    configuration's name and each plate's nodes after joints gave some plates their own copies)."""

    box: object = None
    mesh: BoxMesh | None = None
    configuration: str | None = None
    plate_map: dict | None = None

    def with_shear_factor(self, factor: float) -> "BoxModel":
        """A copy whose shells' transverse shear stiffness is ``factor`` times the declared."""
        return self.with_quantities({SHEAR_KEY: self.quantities[SHEAR_KEY] * factor})

    def plate_nodes(self) -> dict:
        """{plate name: its shell nodes} (a node on a rigid edge belongs to both plates)."""
        return {p.name: np.unique(self.plate_map[p.name][self.mesh.plate_nodes(p.name)]) for p in self.box.plates}

    def layout_hints(self) -> tuple:
        """(suspects {name: node}, footprints {name: plate corners (4, 3)}, thinnest plate [m]) for a
        diagnosis: the declared masses are prime suspects, the plates candidate regions."""
        suspects = {n: v for n, v in self.point_nodes.items() if n.startswith("masses.")}
        footprints = {targets.entry("plates", p.name): p.corners() for p in self.box.plates}
        return suspects, footprints, min(p.thickness for p in self.box.plates)

    def share_groups(self) -> dict:
        """{label: element sets} of the parts a mode's energy is shared among: the plates (ribs with
        their plate)."""
        return {p.name: [n for n in self.model.sets if n.startswith((targets.entry("plates", p.name), *(
            targets.entry("ribs", r.name) for r in self.box.ribs if r.plate == p.name)))] for p in self.box.plates}

    def mode_shares(self, shapes) -> np.ndarray:
        """(n_parts, n_modes): each part's (:meth:`share_groups`) share of each mode's kinetic energy."""
        e = np.array([np.einsum("ij,ij->j", shapes, assemble(self.model, sets=s)[1] @ shapes)
                      for s in self.share_groups().values()])
        return e / np.maximum(e.sum(axis=0), 1e-300)

    def mode_descriptions(self, shapes) -> list:
        """Per mode, the parts that carry most of its kinetic energy, e.g. "upper 71 %, left 12 %"."""
        names = list(self.share_groups())
        out = []
        for col in self.mode_shares(shapes).T:
            order = np.argsort(col)[::-1]
            out.append(", ".join(f"{names[i]} {100 * col[i]:.0f} %" for i in order[:3] if col[i] >= 0.05))
        return out


def _tie_across(model, slave: int, master, e) -> None:
    """The rotations of node ``slave`` about the two axes normal to ``e`` (unit) equal those of node
    ``master`` (None: held at zero); its rotation about ``e`` stays free. The two rotation components
    along which e is smallest are the constrained ones (their 2 x 2 block has determinant +-e_k)."""
    e = np.asarray(e, float)
    k = int(np.argmax(np.abs(e)))
    a = np.cross(e, np.eye(3)[(k + 1) % 3])
    a /= np.linalg.norm(a)
    P = np.vstack([a, np.cross(e, a)])  # rows: the two axes normal to e
    j = [i for i in range(3) if i != k]
    Si = np.linalg.inv(P[:, j])
    s = dof_index(slave)
    m = None if master is None else dof_index(master)
    for row, jj in zip(Si, j):
        terms = [(int(s[3 + k]), -float(row @ P[:, k]))]
        if m is not None:
            terms += [(int(m[3 + i]), float(row @ P[:, i])) for i in range(3)]
        terms = [(d, c) for d, c in terms if abs(c) > 1e-14]
        if terms:
            model.constrain(int(s[3 + jj]), terms)
        else:
            model.fix([slave], (3 + jj,))


def _shell(plate, q: dict):
    """The plate's shell property at quantities ``q``."""
    rho, t = q[targets.target("plates", plate.name, "rho")], q[targets.target("plates", plate.name, "thickness")]
    mat, shear = plate.material, 5.0 / 6.0 * q[SHEAR_KEY]
    if mat.orthotropic:
        return OrthotropicShellProperty(*mat.E, mat.nu, rho, t, axis=tuple(plate.u), shear_factor=shear)
    return ShellProperty(q[targets.target("plates", plate.name, "E")], mat.nu, rho, t, shear_factor=shear)


def initial_quantities(box) -> dict:
    """Every quantity a parameter may address, at the box's values."""
    q = {SHEAR_KEY: 1.0}
    for p in box.plates:
        q[targets.target("plates", p.name, "thickness")] = p.thickness
        q[targets.target("plates", p.name, "rho")] = p.material.rho
        if not p.material.orthotropic:
            q[targets.target("plates", p.name, "E")] = p.material.E
    for r in box.ribs:
        q[targets.target("ribs", r.name, "height")], q[targets.target("ribs", r.name, "width")] = r.height, r.width
    for j in box.joints:
        q[targets.target("joints", j.name, "k_rot")] = j.k_rot
    return q


def _named_points(box, config, shared: bool) -> list:
    """[(name, plate, xyz)] of the points that must be nodes: point masses."""
    masses = [(targets.entry("masses", m.name), m) for m in box.masses]
    for c in (box.configurations if shared else [config] if config is not None else []):
        masses += [(targets.member(targets.entry("configurations", c.name), m.name), m) for m in c.masses]
    return [(name, m.plate, box.plate(m.plate).point(*m.at)) for name, m in masses]


def _joint_nodes(box, mesh, model, plate_map: dict, q: dict, makers: dict) -> None:
    """Each joint's second plate gets its own copy of the shared edge's nodes (``plate_map`` updated),
    tied to the first plate's, and the springs between the two lines of nodes."""
    for j in box.joints:
        a, b = (box.plate(n) for n in j.plates)
        for c in (c for c in box.contacts if set(c.plates) == set(j.plates)):
            chain = mesh.chain(c.start, c.end, mesh.plate_nodes(b.name))
            others = [(d.start, d.end) for d in box.contacts if b.name in d.plates and d is not c]
            others += [b.edge(s.edge) for s in box.supports if s.plate == b.name]
            dup = np.array([not any(segment_gap(x, x, *d) < 1e-7 for d in others) for x in mesh.nodes[chain]])
            new = model.add_nodes(mesh.nodes[chain[dup]])
            plate_map[b.name][chain[dup]] = new
            for orig, copy in zip(chain[dup], new):
                for k in range(3):
                    model.couple(int(dof_index(orig)[k]), int(dof_index(copy)[k]))
                _tie_across(model, int(copy), int(orig), c.direction)
            other = plate_map[b.name][chain]
            cells = np.column_stack([chain[:-1], chain[1:], other[:-1], other[1:]])
            key, name = targets.target("joints", j.name, "k_rot"), targets.entry("joints", j.name)
            name = name if name not in makers else f"{name}#{len(makers)}"
            makers[name] = SetMaker("edge_joint", cells, (key,), lambda q, key=key, n=tuple(a.normal):
                                    EdgeSpringProperty(k=(0.0, 0.0, 0.0, q[key], 0.0, 0.0), normal=n))


def _edge_nodes(box, mesh, plate_map, s) -> np.ndarray:
    """The nodes of support ``s``'s plate along its edge."""
    plate = box.plate(s.plate)
    return plate_map[plate.name][mesh.chain(*plate.edge(s.edge), mesh.plate_nodes(plate.name))]


def _hold(box, mesh, model, plate_map) -> None:
    """The supports: a clamped edge holds every DOF of its nodes, a hinged one their translations and the
    rotations across the edge (about its direction they stay free); where hinged edges of different
    directions meet, nothing is left free to turn."""
    clamped, free_axis = set(), {}
    for s in box.supports:
        nodes = [int(n) for n in _edge_nodes(box, mesh, plate_map, s)]
        if s.type == "clamped":
            model.fix(nodes)
            clamped.update(nodes)
            continue
        model.fix(nodes, supports.TRANSLATIONS)
        p0, p1 = box.plate(s.plate).edge(s.edge)
        for n in nodes:
            free_axis.setdefault(n, []).append((p1 - p0) / np.linalg.norm(p1 - p0))
    for n, axes in free_axis.items():
        if n in clamped:
            continue
        if all(abs(abs(a @ axes[0]) - 1.0) < 1e-9 for a in axes):
            _tie_across(model, n, None, axes[0])
        else:
            model.fix([n], (3, 4, 5))


def build_model(box, config: str | None = None, mesh_size: float | None = None, shared_mesh: bool = False,
                points=(), lines=(), bind: bool = True) -> BoxModel:
    """The FE model of ``box`` in configuration ``config`` (None: the base one); ``shared_mesh``: every
    configuration's masses are nodes, so that all configurations share one mesh node for node.
    ``points`` [(name, plate, xyz)]: more points that must be nodes (in ``point_nodes`` by name),
    ``lines`` [(p0, p1)] more lines element edges follow: where cards meet the housing (and the box's
    ``guides``, :meth:`.box.Box.following`); ``bind``: the
    box's parameters bound (a system binds them once its cards are in)."""
    cfg = configuration_of(box, config, BoxError)
    named = _named_points(box, cfg, shared_mesh) + list(points)
    ribs = [(box.plate(r.plate).point(*r.start), box.plate(r.plate).point(*r.end)) for r in box.ribs]
    ribs += [(a, b) for g in box.guides for a, b in zip(g[:-1], g[1:])]
    size = mesh_size or box.mesh_size
    check_mesh_size(f"{box.path.name}: box.mesh_size", min(min(p.lengths) for p in box.plates),
                    sum(float(np.linalg.norm(np.cross(p.u, p.v))) for p in box.plates), size, BoxError,
                    "the smallest plate's")
    try:
        mesh = mesh_box(box.plates, ribs + list(lines), [p for _, _, p in named], size)
    except RuntimeError as exc:
        raise BoxError(f"{box.path.name}: box.mesh_size: meshing failed ({exc})") from None
    model = Model(mesh.nodes.copy())
    q = initial_quantities(box)
    makers: dict = {}
    plate_map = {p.name: np.arange(len(mesh.nodes)) for p in box.plates}
    _joint_nodes(box, mesh, model, plate_map, q, makers)
    for p in box.plates:
        own = {a: targets.target("plates", p.name, a) for a in ("thickness", "rho", "E")}
        keys = (SHEAR_KEY,) + tuple(k for k in own.values() if k in q)
        linear = {own[a]: 1 for a in ("rho", "E") if own[a] in q}  # M in rho, K in E
        for etype, conn in mesh.cells[p.name].items():
            name = targets.entry("plates", p.name)
            name = name if etype == "quad4" else targets.member(name, etype)
            makers[name] = SetMaker(etype, plate_map[p.name][conn], keys, lambda q, p=p: _shell(p, q),
                                    powers=linear)
    chains = [plate_map[r.plate][mesh.chain(*line, mesh.plate_nodes(r.plate))] for r, line in zip(box.ribs, ribs)]
    if box.rib_model == "beam":
        for r, chain in zip(box.ribs, chains):
            plate = box.plate(r.plate)
            m = plate.normal * (1.0 if r.side == "+n" else -1.0)
            keys = (targets.target("ribs", r.name, "height"), targets.target("ribs", r.name, "width"),
                    targets.target("plates", plate.name, "thickness"))
            makers[targets.entry("ribs", r.name)] = SetMaker(
                "beam2", np.column_stack([chain[:-1], chain[1:]]), keys,
                lambda q, r=r, m=m, k=keys: rib_section(r.material.E, r.material.nu, r.material.rho, q[k[0]], q[k[1]],
                                                        m, q[k[2]]), powers=dict.fromkeys(keys[:2]))
    else:
        strips = [(targets.entry("ribs", r.name), chain, box.plate(r.plate).normal * (1.0 if r.side == "+n" else -1.0),
                   box.plate(r.plate).thickness, r.height, r.width, r.material) for r, chain in zip(box.ribs, chains)]
        made, ends = add_strips(model, strips, size)
        for name, conn, prop in made:
            makers[name] = SetMaker("quad4", conn, (SHEAR_KEY,),
                                    lambda q, prop=prop: replace(prop, shear_factor=5.0 / 6.0 * q[SHEAR_KEY]))
        hold_ends(model, ends, {int(n): s.type for s in box.supports for n in _edge_nodes(box, mesh, plate_map, s)})
    _hold(box, mesh, model, plate_map)
    point_nodes = {name: int(plate_map[plate][n]) for (name, plate, _), n in zip(named, mesh.point_nodes)}
    masses = [(targets.entry("masses", m.name), m) for m in box.masses]
    masses += [(targets.member(targets.entry("configurations", cfg.name), m.name), m) for m in (cfg.masses if cfg else [])]
    for name, m in masses:
        n, etype, conn, deps, make = supports.point_mass(name, point_nodes[name], m, q)
        makers[n] = SetMaker(etype, np.asarray(conn, dtype=np.int64), deps, make)
    model.free = not box.supports
    model.node_groups.update({name: np.array([n]) for name, n in point_nodes.items()})
    bm = BoxModel.assemble_from(model, q, makers, point_nodes=point_nodes, box=box, mesh=mesh, configuration=config,
                                plate_map=plate_map)
    if bind:
        bm.bind(box.parameters)
    return bm
