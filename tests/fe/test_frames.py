"""A model described in its own frame and placed by a rotation (pcbdyn.fe.frames) has the modes of the
model itself: the element sets are formed in local axes and turned, the constraints written on local
DOFs (partial fixes, a node following the least-squares motion of others) re-expressed on global ones."""

import numpy as np

from pcbdyn.fe import MassProperty, Model, OrthotropicShellProperty, SpringProperty, dof_index
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.frames import idle_dofs, placed
from pcbdyn.fe.generate import nodes_where, rectangle
from pcbdyn.fe.modal import solve_modes


def _local():
    nodes, conn = rectangle(0.16, 0.10, 16, 10)
    m = Model(nodes)
    m.add("plate", "quad4", conn, OrthotropicShellProperty(30e9, 18e9, 0.2, 1900.0, 1.6e-3, axis=(0.8, 0.6, 0.0)))
    left = nodes_where(nodes, x=0.0)
    m.fix(left, ("ux", "uy", "uz", "rx", "rz"))  # a hinge about y: not a whole vector held
    c = int(m.add_nodes([[0.1, 0.05, 0.0]])[0])
    foot = np.flatnonzero(np.linalg.norm(nodes[:, :2] - [0.1, 0.05], axis=1) < 0.015)
    dofs = dof_index(foot)
    m.constrain(int(dof_index(c)[2]), [(int(d), 1.0 / foot.size) for d in dofs[:, 2]])  # w: the mean of the footprint
    for k in (0, 1, 3, 4):
        m.constrain(int(dof_index(c)[k]), [(int(d), 1.0 / foot.size) for d in dofs[:, k]])
    m.add("part", "mass", [[c]], MassProperty(0.05, (2e-5, 3e-5, 0.0)))
    m.add("spring", "spring", [[int(nodes_where(nodes, x=0.16, y=0.10)[0])]], SpringProperty(k=(0, 0, 4e4, 0, 0, 0)))
    return m


def test_a_placed_model_keeps_its_modes():
    local = _local()
    ref = solve_modes(local, 8).frequencies
    a = np.array([0.3, -0.5, 0.8])
    a /= np.linalg.norm(a)
    ang = 1.1
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    R = np.eye(3) + np.sin(ang) * K + (1 - np.cos(ang)) * K @ K
    other = Model(np.array([[5.0, 5.0, 5.0]]))  # a node before the part: its numbers shift
    other.fix([0])
    nodes, fixed, mpcs = placed(local, R, (0.2, -0.1, 0.4), first_node=1, idle=idle_dofs(local, *assemble(local)))
    g = Model(np.vstack([other.nodes, nodes]))
    g.fixed |= other.fixed | fixed
    g.mpcs += mpcs
    for name, es in local.sets.items():
        g.add(name, es.etype, es.conn + 1, es.prop, frame=R)
    got = solve_modes(g, 8).frequencies
    assert np.allclose(got, ref, rtol=1e-9), (got, ref)
    assert not np.allclose(nodes[:, 2], nodes[0, 2])  # the plate is no longer in a plane z = const
