"""Element sets of the board entries that declare effects a diagnosis can find (issue 7): point and
edge springs to ground, line masses, stiffeners and regions of scaled stiffness.

Each builds exactly what the diagnosis kind of the same effect adds to an FE model
(``pcbdyn.diagnosis``: ground_spring, edge_stiffness, line_mass, stiffener, region_stiffness,
region_mass), so
that a board declaring a diagnosed effect has the same matrices as the diagnosed model:

- point spring: a spring to ground on the node's z translation, k (N/m);
- edge spring: a rotational spring per unit length about the segment direction (edge-frame
  axis 1, whatever the segment's direction), distributed consistently on its element edges;
- line mass: the mass lumped on the segment's nodes by tributary length, on x, y and z;
- stiffener: a beam of fixed material and height h whose width b follows from EI = E b h^3 / 12,
  A = b h, Iy = Iz = b h^3 / 12, J = b h^3 / 3, axis offset (t + h) / 2 above the mid-surface;
- region: the shells whose centroid lies inside the polygon get their stiffness (membrane,
  bending, shear) multiplied by the factor (overlapping regions multiply), and its mass, if any,
  lumped at their nodes by tributary area on x, y and z.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.path import Path as PolyPath

from .. import targets
from ..fe import BeamProperty, EdgeSpringProperty, MassProperty, SpringProperty
from ..fe.model import SHELL_TYPES
from .entries import BoardError, RibSection


def rib_property(EI: float, plate_thickness: float, section: RibSection = RibSection(),
                 normal=(0.0, 0.0, 1.0)) -> BeamProperty:
    """The stiffener's beam section for bending stiffness ``EI`` [N m^2] on a plate of thickness
    ``plate_thickness`` (the diagnosis kind's RibSection.prop), standing on the side of the plate that its
    unit ``normal`` points to (a board's +z; a housing wall's inside); its bending is linear, as the
    shell's it is tied to (on a node row or embedded across cells alike)."""
    b = 12.0 * EI / (section.E * section.h**3)
    inertia = b * section.h**3 / 12.0
    n = np.asarray(normal, float)
    return BeamProperty(section.E, section.nu, section.rho, b * section.h, inertia, inertia, 4.0 * inertia,
                        orientation=tuple(n), offset=tuple(0.5 * (plate_thickness + section.h) * n),
                        linear_bending=True)


def edge_spring_property(k_rot: float) -> EdgeSpringProperty:
    """Rotational stiffness per unit length about the edge (the diagnosis edge_stiffness kind)."""
    return EdgeSpringProperty(k=(0.0, 0.0, 0.0, k_rot, 0.0, 0.0), normal=(0.0, 0.0, 1.0))


def tributary_weights(xy: np.ndarray) -> np.ndarray:
    """Tributary-length fractions of the nodes of a chain (sum 1)."""
    L = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    w = np.r_[L, 0.0] + np.r_[0.0, L]
    return w / w.sum()


def area_weights(xy: np.ndarray, conns, nodes: np.ndarray) -> np.ndarray:
    """Tributary-area fractions (sum 1) of ``nodes`` over the cells ``conns`` (arrays of node rows,
    polygons in the plane of ``xy`` (n, 2)): each cell's area shared equally by its corners."""
    w = np.zeros(len(xy))
    for conn in conns:
        p, q = xy[conn], xy[np.roll(conn, -1, axis=1)]
        area = 0.5 * np.abs(np.sum(p[..., 0] * q[..., 1] - q[..., 0] * p[..., 1], axis=1))
        np.add.at(w, conn, np.repeat(area / conn.shape[1], conn.shape[1]).reshape(conn.shape))
    return w[nodes] / w[nodes].sum()


@dataclass(frozen=True)
class ScaledShell:
    """A shell property whose stiffness is ``factor`` times that of ``base`` (mass unchanged)."""

    base: object
    factor: float

    def membrane(self):
        return self.factor * np.asarray(self.base.membrane())

    def bending(self):
        return self.factor * np.asarray(self.base.bending())

    def shear(self):
        return self.factor * np.asarray(self.base.shear())

    def mass_per_area(self):
        return self.base.mass_per_area()

    def rotary_inertia_per_area(self):
        return self.base.rotary_inertia_per_area()

    @property
    def t(self):
        return self.base.t


def _chain(board, mesh, segment, where) -> np.ndarray:
    try:
        return mesh.chain_on_segment(*segment)
    except RuntimeError as exc:
        raise BoardError(f"{board.path.name}: {where}: {exc}; change board.mesh_size slightly") from None


def _path_edges(board, mesh, path, where) -> np.ndarray:
    return np.concatenate([np.column_stack([c[:-1], c[1:]]) for c in
                           (_chain(board, mesh, (a, b), where) for a, b in zip(path[:-1], path[1:]))])


def apply_fixture(board, mesh, f, point_nodes: dict, q: dict) -> list:
    """Makers [(name, etype, conn, deps, make)] of a point_spring or edge_spring fixture."""
    if f.type == "point_spring":
        key, name = targets.target("fixtures", f.name, "k"), targets.entry("fixtures", f.name)
        q.setdefault(key, float(f.k))
        return [(name, "spring", [[point_nodes[name]]], (key,),
                 lambda q, key=key: SpringProperty(k=(0.0, 0.0, q[key], 0.0, 0.0, 0.0)))]
    key, name = targets.target("fixtures", f.name, "k_rot"), targets.entry("fixtures", f.name)
    q.setdefault(key, float(f.k_rot))
    chain = _chain(board, mesh, f.segment, name)
    return [(name, "edge_spring", np.column_stack([chain[:-1], chain[1:]]), (key,),
             lambda q, key=key: edge_spring_property(q[key]))]


def effect_sets(board, mesh, q: dict, makers: dict) -> list:
    """Makers of the line masses and stiffeners; regions re-make the shell makers in ``makers``
    in place (their cells inside a region move to ``regions.<name>.<set>``)."""
    out = []
    for e in board.line_masses:
        key, name = targets.target("line_masses", e.name, "mass"), targets.entry("line_masses", e.name)
        q.setdefault(key, e.mass)
        chain = _chain(board, mesh, e.segment, name)
        for k, (n, w) in enumerate(zip(chain, tributary_weights(mesh.nodes[chain, :2]))):
            out.append((targets.member(name, str(k)), "mass", [[int(n)]], (key,),
                        lambda q, key=key, w=w: MassProperty(q[key] * w)))
    for e in board.stiffeners:
        key, name = targets.target("stiffeners", e.name, "EI"), targets.entry("stiffeners", e.name)
        q.setdefault(key, e.EI)
        edges = _path_edges(board, mesh, e.path, name)
        out.append((name, "beam2", edges, (key, "board.thickness"),
                    lambda q, key=key, s=e.section: rib_property(q[key], q.get("board.thickness", board.plate.t), s)))
    for e in board.regions:
        key = targets.target("regions", e.name, "stiffness_factor")
        q.setdefault(key, e.stiffness_factor)
        path = PolyPath(e.polygon)
        cells = []
        for name in list(makers):
            mk = makers[name]
            if mk.etype not in SHELL_TYPES or not len(mk.conn):
                continue
            inside = path.contains_points(mesh.nodes[mk.conn][:, :, :2].mean(axis=1))
            if not inside.any():
                continue
            cells.append(mk.conn[inside])
            new = targets.member(targets.entry("regions", e.name), name)
            makers[new] = type(mk)(mk.etype, mk.conn[inside], mk.deps + (key,),
                                   lambda q, key=key, make=mk.make: ScaledShell(make(q), q[key]))
            if inside.all():
                del makers[name]
            else:
                makers[name] = type(mk)(mk.etype, mk.conn[~inside], mk.deps, mk.make)
        if e.mass is not None and cells:
            mkey, entry = targets.target("regions", e.name, "mass"), targets.entry("regions", e.name)
            q.setdefault(mkey, e.mass)
            nodes = np.unique(np.concatenate([c.ravel() for c in cells]))
            for k, (n, w) in enumerate(zip(nodes, area_weights(mesh.nodes[:, :2], cells, nodes))):
                out.append((targets.member(entry, f"mass{k}"), "mass", [[int(n)]], (mkey,),
                            lambda q, key=mkey, w=w: MassProperty(q[key] * w)))
    return out
