"""Small models shared by the diagnosis tests."""

import numpy as np
import pytest

from pcbdyn.fe import EdgeSpringProperty, MassProperty, Model, ShellProperty
from pcbdyn.fe.generate import nodes_where, rectangle
from pcbdyn.fe.modal import solve_modes

A, B = 0.1, 0.08  # plate sides [m]
PLATE = ShellProperty(E=20e9, nu=0.3, rho=1900.0, t=1.6e-3)
N_MODES = 6


def cantilever(nx=10, ny=8):
    """A 100 x 80 x 1.6 mm plate clamped along x = 0 (small enough for the dense eigensolver)."""
    nodes, conn = rectangle(A, B, nx, ny)
    m = Model(nodes)
    m.add("plate", "quad4", conn, PLATE)
    m.fix(nodes_where(nodes, x=0.0))
    return m


def guided_card(nx=12, ny=14, E=26e9):
    """A 160 x 180 x 2.8 mm card in two guides (x = 0 and x = 160 mm, kr = 300 N m/rad/m), about 13
    mm elements, carrying a declared 30 g mass off-centre (it breaks the mirror symmetries that
    frequencies alone cannot resolve); the laminate's modulus ``E`` [Pa]."""
    nodes, conn = rectangle(0.16, 0.18, nx, ny)
    m = Model(nodes)
    m.add("plate", "quad4", conn, ShellProperty(E, 0.3, 2640.0, 2.8e-3))
    for x in (0.0, 0.16):
        e = nodes_where(nodes, x=x)
        m.fix(e, ("ux", "uy", "uz", "rx", "rz"))
        m.add(f"guide{x}", "edge_spring", np.c_[e[:-1], e[1:]], EdgeSpringProperty(k=(0, 0, 0, 300.0, 0, 0)))
    m.add("declared", "mass", [[node_at(m, 0.12, 0.05)]], MassProperty(0.03))
    return m


def node_at(model, x, y):
    return int(np.linalg.norm(model.nodes[:, :2] - [x, y], axis=1).argmin())


def frequencies(model, n=N_MODES):
    return solve_modes(model, n_modes=n).frequencies


def total_mass(model, dof=2):
    """r^T M r with r = 1 on one DOF of every node (dof 2: translational mass in z)."""
    from pcbdyn.fe.assembly import assemble

    _, M = assemble(model)
    r = np.zeros(model.n_dof)
    r[dof::6] = 1.0
    return float(r @ (M @ r))


def rotary_inertia(model, axis: int, about) -> float:
    """r^T M r of a unit rigid rotation about global ``axis`` through the point ``about``."""
    from pcbdyn.fe.assembly import assemble

    _, M = assemble(model)
    e = np.eye(3)[axis]
    r = np.zeros((model.n_nodes, 6))
    r[:, :3] = np.cross(e, model.nodes - np.asarray(about, float))
    r[:, 3:] = e
    r = r.ravel()
    return float(r @ (M @ r))


def measured(f, shapes=None, xyz=None, directions=(0.0, 0.0, 1.0)):
    """Measured modes (pcbdyn.testdata.MeasuredModes) of frequencies ``f``, with ``shapes`` at points ``xyz``
    (default: the origin, for residuals that read shapes through a given matrix) along ``directions``."""
    from pcbdyn.testdata import Dofs, MeasuredModes, Points

    if shapes is None:
        return MeasuredModes.frequencies_only(f)
    shapes = np.asarray(shapes, float)
    n = shapes.shape[0]
    ids = np.arange(1, n + 1)
    xyz = np.zeros((n, 3)) if xyz is None else np.asarray(xyz, float)
    return MeasuredModes(Points(ids, xyz), Dofs(ids, directions), f, shapes)


def check_parameter_columns(res, p, m: int, h: float = 1e-5):
    """The residual's first parameter column at ``p`` against central differences of full re-solves
    (``m`` measured modes): frequency rows exact, shape rows within 5 % (cosine > 0.99)."""
    a = res.param_columns(res.evaluate(p))[:, 0]
    fd = -(res.evaluate(p * np.exp(h)).r - res.evaluate(p * np.exp(-h)).r) / (2 * h)
    assert np.allclose(a[:m], fd[:m], rtol=1e-4)
    s, sf = a[m:], fd[m:]
    assert s @ sf / (np.linalg.norm(s) * np.linalg.norm(sf)) > 0.99
    assert np.linalg.norm(s) == pytest.approx(np.linalg.norm(sf), rel=0.05)
