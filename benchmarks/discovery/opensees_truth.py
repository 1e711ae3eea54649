"""Hold-out modal data from an independent FE code: a :class:`pcbdyn.fe.Model` converted to
OpenSees (openseespy) and solved there, so that pcbdyn's diagnosis can be tested on modes that
pcbdyn's own elements and solver never produced.

Conversion (OpenSees node tag = pcbdyn node index + 1; the model's fixed DOFs become ``fix``):

- quad4 / tri3 shells: ``ShellDKGQ`` / ``ShellDKGT`` by default, or ``ShellMITC4`` (with
  ``ShellDKGT``) or ``ASDShellQ4`` (with ``ASDShellT3``), on an ``ElasticMembranePlateSection``
  with rho_eff = rho + nsm / t. A ``ScaledShell`` (stiffness x factor, mass unchanged) is
  E x factor with rho unchanged. Shell mass is translational only (no rotary inertia
  rho t^3 / 12). DKGQ is a Kirchhoff plate (no transverse shear, unlike pcbdyn's shell): on the
  free card it is 0.2-1.3 % stiffer than pcbdyn, and stays so with mesh refinement (twist near
  free edges); ASDShellQ4 reproduces pcbdyn to 0.1 %.
- beam2: ``elasticBeamColumn`` (``ElasticTimoshenkoBeam`` if shear areas are given) with
  consistent mass rho A, local axes through ``vecxz`` = pcbdyn's local z (OpenSees: y = vecxz x x,
  so OpenSees' y, z and Iy, Iz are pcbdyn's). An offset section runs between extra axis nodes at
  node + offset, each tied to its node by ``rigidLink('beam')`` (OpenSees' ``-jntOffset`` offsets
  the stiffness but leaves the mass at the nodes). The section's rotary inertia (torsion, and
  bending where pcbdyn's property has it), which OpenSees' beams lack, is lumped at the axis nodes
  (:func:`_beams`).
- spring: ``zeroLength`` to a new fixed node (1-node cells) or between the nodes (2-node cells),
  one ``Elastic`` material per nonzero term in the spring's principal axes (a 6x6 k must have
  no translation-rotation coupling).
- edge_spring: LUMPED, k L / 2 per cell end as a ``zeroLength`` to ground oriented in the edge
  frame (pcbdyn integrates it consistently along the edge).
- mass: m on the body's node; its rotary inertia shared equally, as nodal rotary inertia, by the
  nodes of its footprint (pcbdyn ties the body to the least-squares rigid motion of the
  footprint; one node's rotations alone would carry a large inertia as a local rocking mode on
  a fine mesh).
- multi-point constraints: a node tied to one other by all six rows of a rigid link (a standoff's
  pad to its centre) becomes ``rigidLink('beam')``; a node whose rows follow several nodes (a lumped
  part that moves with its footprint's least-squares rigid motion) is held, and its mass shared
  equally by those nodes, with its rotary inertia less the m r^2 the sharing adds (clipped at zero):
  the footprint then carries the part's mass and, as long as it moves as a plane, its inertia.
  OpenSees has no general linear constraint, so this is a modelling difference of its own. Three
  others were worse: the mass on the footprint node nearest the centre loads a Mindlin plate at one
  node, a local flexibility that grows as the mesh is refined (dev seed 3 meshed as its truth,
  ASDShellQ4 against pcbdyn: modes 3, 6, 7, 10 at -2.7, -2.4, -3.4, -4.7 %, against -0.2, -0.2,
  -0.5, -0.7 % now; 9.6 g at 14.7 mm alone: -14 % on its eleventh mode); shared out with all of its
  rotary inertia, it added m r^2, which the diagnosis duly found as an effect on noise-only data;
  embedded in a triangle of its footprint (``ASDEmbeddedNodeElement``): -2.6 to +2.4 % on the
  model's mesh. Anything else raises NotImplementedError.
- embedded_beam2: not supported (NotImplementedError).
"""

from __future__ import annotations

import numpy as np
import openseespy.opensees as ops

SHELLS = {"ShellDKGQ": "ShellDKGT", "ShellMITC4": "ShellDKGT", "ASDShellQ4": "ASDShellT3"}
RIGID_HZ = 1.0  # free models: modes below this are rigid-body modes


class _Tags:
    def __init__(self):
        self.n = 0

    def __call__(self) -> int:
        self.n += 1
        return self.n


def _shell_section(prop, tag: int) -> None:
    factor = 1.0
    if hasattr(prop, "base") and hasattr(prop, "factor"):  # pcbdyn.board.effects.ScaledShell
        prop, factor = prop.base, prop.factor
    for a in ("E", "nu", "rho", "t"):
        if not hasattr(prop, a):
            raise NotImplementedError(f"shell property {type(prop).__name__} is not an isotropic ShellProperty")
    ops.section("ElasticMembranePlateSection", tag, prop.E * factor, prop.nu, prop.t,
                prop.rho + getattr(prop, "nsm", 0.0) / prop.t)


def _ground(xyz, ground_tag: _Tags) -> int:
    t = ground_tag()
    ops.node(t, *np.asarray(xyz, float).tolist())
    ops.fix(t, 1, 1, 1, 1, 1, 1)
    return t


def _zero_length(tags, mat_tags, nodes, k6, R) -> None:
    """zeroLength between ``nodes`` with stiffness k6 (6,) along the rows of R (local x, y, z)."""
    dirs = [i for i in range(6) if k6[i] != 0.0]
    if not dirs:
        return
    mats = []
    for i in dirs:
        mats.append(mat_tags())
        ops.uniaxialMaterial("Elastic", mats[-1], float(k6[i]))
    ops.element("zeroLength", tags(), *nodes, "-mat", *mats, "-dir", *[i + 1 for i in dirs],
                "-orient", *R[0].tolist(), *R[1].tolist())


def _principal(k) -> list:
    """[(k6, R)]: a spring's diagonal values and local axes (rows of R)."""
    k = np.asarray(k, dtype=float)
    if k.shape == (6,):
        return [(k, np.eye(3))]
    if np.any(k[:3, 3:] != 0.0):
        raise NotImplementedError("spring with translation-rotation coupling")
    out = []
    for blk, sl in ((k[:3, :3], slice(0, 3)), (k[3:, 3:], slice(3, 6))):
        w, V = np.linalg.eigh(blk)
        k6 = np.zeros(6)
        k6[sl] = w
        out.append((k6, V.T))
    return out


def _beams(model, es, ele, trf, extra, mass) -> None:
    """Beam cells on axis nodes at node + offset, each tied to its node by a rigid link (OpenSees'
    ``-jntOffset`` leaves the element mass at the nodes, which is wrong for an offset rib). The
    section's torsional inertia rho (Iy + Iz) L, which OpenSees' beams lack, is lumped half at each
    end's axis node (on a node of the model: into ``mass``), with the rotary inertia in bending rho Iy,
    rho Iz about the section's axes where the property has it (``rotary_inertia``, as pcbdyn's beam
    does), as the diagonal of the tensor in global axes: exact for beams along an axis (a housing's
    ribs), the oblique ones' cross terms dropped. Without them a tall rib rocked too lightly: housing
    seed 0 (16.8 x 3.65 mm ribs) read modes 8 and 9 0.5 and 1.3 % above pcbdyn's at the same mesh."""
    p, X = es.prop, model.nodes
    bending = 1.0 if getattr(p, "rotary_inertia", False) else 0.0
    G = p.E / (2.0 * (1.0 + p.nu))
    off = np.asarray(p.offset, dtype=float)
    axis, rotary = {}, {}
    for a in np.unique(es.conn):
        if np.any(off != 0.0):
            axis[a] = extra()
            ops.node(axis[a], *(X[a] + off).tolist())
            ops.rigidLink("beam", int(a) + 1, axis[a])
        else:
            axis[a] = int(a) + 1
    for c in es.conn:
        x = X[c[1]] - X[c[0]]
        x /= np.linalg.norm(x)
        y = np.asarray(p.orientation, float) - (x @ p.orientation) * x
        y /= np.linalg.norm(y)
        z = np.cross(x, y)  # pcbdyn's local z, in OpenSees' local x-z plane
        t = trf()
        ops.geomTransf("Linear", t, *z.tolist())
        ends = [axis[c[0]], axis[c[1]]]
        share = 0.5 * p.rho * np.linalg.norm(X[c[1]] - X[c[0]]) * (
            (p.Iy + p.Iz) * x * x + bending * (p.Iz * y * y + p.Iy * z * z))
        for a, tag in zip(c, ends):
            if np.any(off != 0.0):
                rotary[tag] = rotary.get(tag, 0.0) + share
            else:
                mass[a, 3:] += share
        if p.shear_area_y or p.shear_area_z:
            Ay = p.shear_area_y or 1e6 * p.A  # None: no shear flexibility in that plane
            Az = p.shear_area_z or 1e6 * p.A
            ops.element("ElasticTimoshenkoBeam", ele(), *ends, p.E, G, p.A, p.J, p.Iy, p.Iz, Ay, Az, t,
                        "-mass", p.rho * p.A, "-cMass")
        else:
            ops.element("elasticBeamColumn", ele(), *ends, p.A, p.E, G, p.J, p.Iy, p.Iz, t,
                        "-mass", p.rho * p.A, "-cMass")
    for tag, J in rotary.items():
        ops.mass(tag, 0.0, 0.0, 0.0, *J.tolist())


def _constraints(model) -> tuple:
    """(rigid links [(master, slave)], followers {node: [nodes it follows]}) of ``model.mpcs``."""
    rows: dict = {}
    for s, terms in model.mpcs:
        rows.setdefault(s // 6, []).append((s % 6, terms))
    links, followers = [], {}
    for node, rs in rows.items():
        masters = sorted({m // 6 for _, terms in rs for m, _ in terms})
        if len(masters) == 1 and sorted(d for d, _ in rs) == list(range(6)):
            links.append((masters[0], node))
        elif len(masters) > 1:
            followers[node] = masters
        else:
            raise NotImplementedError(f"multi-point constraint of node {node}: {rs}")
    return links, followers


def build_opensees(model, shell: str = "ShellDKGQ") -> None:
    """Build ``model`` in the (wiped) OpenSees domain."""
    links, followers = _constraints(model)
    if shell not in SHELLS:
        raise ValueError(f"shell must be one of {sorted(SHELLS)}")
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    ops.constraints("Transformation")  # rigid links of offset beams
    n = model.n_nodes
    X = model.nodes
    for i in range(n):
        ops.node(i + 1, *X[i].tolist())
    ele, mat, sec, trf = _Tags(), _Tags(), _Tags(), _Tags()
    ground = _Tags()
    ground.n = n
    mass = np.zeros((n, 6))
    stiff = np.zeros(n, dtype=bool)  # nodes held by some element
    for es in model.sets.values():
        conn, prop = es.conn, es.prop
        if es.etype in ("quad4", "tri3"):
            s = sec()
            _shell_section(prop, s)
            name = shell if es.etype == "quad4" else SHELLS[shell]
            for c in conn:
                ops.element(name, ele(), *(c + 1).tolist(), s)
        elif es.etype == "beam2":
            _beams(model, es, ele, trf, ground, mass)
        elif es.etype == "spring":
            for k6, R in _principal(prop.k):
                for c in conn:
                    nodes = [int(c[0]) + 1, _ground(X[c[0]], ground)] if c.size == 1 else (c + 1).tolist()
                    _zero_length(ele, mat, nodes, k6, R)
        elif es.etype == "edge_spring":
            k = np.asarray(prop.k, dtype=float)
            for c in conn:
                d = X[c[1]] - X[c[0]]
                L = np.linalg.norm(d)
                e1 = d / L
                e3 = np.asarray(prop.normal, float) - (e1 @ prop.normal) * e1
                e3 /= np.linalg.norm(e3)
                R = np.stack([e1, np.cross(e3, e1), e3])
                for a in c:
                    _zero_length(ele, mat, [int(a) + 1, _ground(X[a], ground)], 0.5 * L * k, R)
        elif es.etype == "mass":
            J = np.asarray(prop.inertia, float)
            J = np.diag(J) if J.ndim == 1 else J
            if np.any(J != np.diag(np.diag(J))):
                raise NotImplementedError("mass with off-diagonal inertia")
            J = np.diag(J)
            for c in conn:  # a footprint cell lists the body's own node first
                mass[c[0], :3] += prop.m
                mass[c, 3:] += J / c.size
        elif es.etype == "embedded_beam2":
            raise NotImplementedError("embedded_beam2 is not converted")
        else:
            raise NotImplementedError(f"element type {es.etype}")
        if es.etype != "mass":
            stiff[np.unique(conn)] = True
    for node, masters in followers.items():
        m, d = mass[node, 0], X[masters] - X[node]
        spread = m / len(masters) * ((d * d).sum(axis=1)[:, None] - d * d).sum(axis=0)  # its m r^2 about each axis
        mass[masters, :3] += m / len(masters)
        mass[masters, 3:] += np.clip(mass[node, 3:] - spread, 0.0, None) / len(masters)
        mass[node] = 0.0
    for master, slave in links:
        ops.rigidLink("beam", int(master) + 1, int(slave) + 1)
        stiff[[master, slave]] = True
    for i in np.flatnonzero(mass.any(axis=1)):
        ops.mass(int(i) + 1, *mass[i].tolist())
    flags = np.zeros((n, 6), dtype=int)
    fixed = np.fromiter(model.fixed, dtype=np.int64, count=len(model.fixed))
    flags.flat[fixed] = 1
    loose = ~stiff & mass.any(axis=1)
    if np.any(loose):
        raise ValueError(f"nodes {np.flatnonzero(loose)[:5].tolist()} carry mass but no element")
    flags[~stiff] = 1  # nodes of no element: held (their shapes are zero)
    for i in np.flatnonzero(flags.any(axis=1)):
        ops.fix(int(i) + 1, *flags[i].tolist())


def solve_opensees(model, n_modes: int, shell: str = "ShellDKGQ", solver: str = "-genBandArpack"):
    """(frequencies [Hz] (n_modes,), shapes (n_nodes, 6, n_modes), not mass-normalised) of the
    first ``n_modes`` elastic modes of ``model`` computed by OpenSees (ARPACK, MUMPS factorisation);
    a free model's rigid-body modes (below ``RIGID_HZ``) are dropped."""
    build_opensees(model, shell)
    # MUMPS: fastest measured (UmfPack, ProfileSPD 4-5x slower, BandGen 2x); with the default
    # system, DKGQ's massless drilling DOFs gave spurious modes
    ops.system("Mumps")
    n_ask = n_modes + (6 if model.free else 0)
    lam = np.asarray(ops.eigen(solver, n_ask), dtype=float)
    f = np.sqrt(np.abs(lam)) / (2.0 * np.pi)
    keep = np.flatnonzero(f >= RIGID_HZ if model.free else np.ones(f.size, bool))[:n_modes]
    if keep.size < n_modes:
        raise RuntimeError(f"OpenSees gave {keep.size} elastic modes of {n_modes} wanted: {f}")
    shapes = np.zeros((model.n_nodes, 6, keep.size))
    for j, m in enumerate(keep):
        for i in range(model.n_nodes):
            shapes[i, :, j] = ops.nodeEigenvector(i + 1, int(m) + 1)
    ops.wipe()
    return f[keep], shapes
