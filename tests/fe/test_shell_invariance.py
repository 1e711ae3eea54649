"""Patch-type checks of the flat shells: exact rigid-body modes, frame invariance, total mass."""

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve

from pcbdyn.fe import Model, ModelError, ShellProperty
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle
from pcbdyn.fe.modal import solve_modes

PROP = ShellProperty(E=70e9, nu=0.33, rho=2700.0, t=2e-3)
KINDS = ["quad4", "tri3"]


def rotation(seed):
    """A random proper rotation matrix."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def distorted_plate(kind, seed=0):
    """0.3 x 0.2 m plate, 8 x 6 grid with interior nodes moved randomly (irregular elements)."""
    nodes, conn = rectangle(0.3, 0.2, 8, 6, kind)
    interior = (nodes[:, 0] > 0) & (nodes[:, 0] < 0.3) & (nodes[:, 1] > 0) & (nodes[:, 1] < 0.2)
    shift = np.random.default_rng(seed).uniform(-0.008, 0.008, size=(interior.sum(), 2))
    nodes[interior, :2] += shift
    return nodes, conn


def placed(nodes, seed):
    """The nodes rotated arbitrarily in 3-D and moved."""
    return nodes @ rotation(seed).T + np.array([0.4, -1.3, 2.2])


def free_model(nodes, conn, kind, prop=PROP):
    model = Model(nodes)
    model.add("shell", kind, conn, prop)
    model.free = True
    return model


def rigid_motions(nodes):
    """Six full-length vectors: unit translations x, y, z and unit rotations about x, y, z."""
    n = len(nodes)
    R = np.zeros((n, 6, 6))
    for k in range(3):
        R[:, k, k] = 1.0
        e = np.eye(3)[k]
        R[:, :3, 3 + k] = np.cross(e, nodes)
        R[:, 3 + k, 3 + k] = 1.0
    return R.reshape(6 * n, 6)


@pytest.mark.parametrize("kind", KINDS)
def test_rigid_motions_are_strain_free_in_any_orientation(kind):
    nodes, conn = distorted_plate(kind)
    nodes = placed(nodes, seed=3)
    K, _ = assemble(free_model(nodes, conn, kind))
    R = rigid_motions(nodes)
    gross = abs(K) @ np.abs(R)
    assert np.abs(K @ R).max() < 1e-12 * gross.max()


@pytest.mark.parametrize("kind", KINDS)
def test_free_mesh_has_six_rigid_modes_and_is_frame_invariant(kind):
    nodes, conn = distorted_plate(kind)
    flat = solve_modes(free_model(nodes, conn, kind), n_modes=12)
    moved = solve_modes(free_model(placed(nodes, seed=7), conn, kind), n_modes=12)
    assert flat.n_rigid == 6 and moved.n_rigid == 6
    # the first elastic mode is a plate mode: compare with the thin free-plate estimate
    # (a 0.3 x 0.2 plate lies between squares of 0.2 and 0.3 m; lambda^2 of a square ~ 13.5)
    D = PROP.bending()[0, 0]
    f_square = lambda a: 13.5 / (2 * np.pi * a**2) * np.sqrt(D / (PROP.rho * PROP.t))
    assert f_square(0.3) / 3 < flat.frequencies[0] < 3 * f_square(0.2)
    np.testing.assert_allclose(moved.frequencies, flat.frequencies, rtol=1e-6)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("nsm", [0.0, 1.7])
def test_rigid_translation_carries_the_total_mass(kind, nsm):
    prop = ShellProperty(E=70e9, nu=0.33, rho=2700.0, t=2e-3, nsm=nsm)
    nodes, conn = distorted_plate(kind)
    nodes = placed(nodes, seed=11)
    _, M = assemble(free_model(nodes, conn, kind, prop))
    R = rigid_motions(nodes)[:, :3]
    expected = (prop.rho * prop.t + nsm) * 0.3 * 0.2
    np.testing.assert_allclose(R.T @ (M @ R), expected * np.eye(3), rtol=1e-9, atol=1e-12 * expected)


@pytest.mark.parametrize("kind", KINDS)
def test_folded_plate_in_3d_floats_with_six_rigid_modes(kind):
    """Two plates meeting at a right-angle fold and a third at 60 deg: the drilling rotation of
    one is a bending rotation of the other, and the assembly must still have exactly six
    zero-frequency modes."""
    base, conn = rectangle(0.2, 0.1, 6, 3, kind)
    wall = base.copy()
    wall[:, 2], wall[:, 1] = wall[:, 1], 0.0  # x-z plane sharing the edge y = 0
    slant = base.copy()
    slant[:, 1], slant[:, 2] = 0.1 + 0.5 * base[:, 1], np.sqrt(0.75) * base[:, 1]  # from the edge y = 0.1
    all_nodes = np.vstack([base, wall, slant])
    key = np.round(all_nodes / 1e-9).astype(np.int64)
    _, first, merged = np.unique(key, axis=0, return_index=True, return_inverse=True)
    merged = merged.ravel()
    n = len(base)
    cells = np.vstack([merged[conn], merged[conn + n], merged[conn + 2 * n]])
    modes = solve_modes(free_model(all_nodes[first], cells, kind), n_modes=3)
    assert modes.n_rigid == 6
    assert modes.frequencies[0] > 1.0


def test_bad_shell_input_is_named():
    nodes, conn = rectangle(0.3, 0.2, 2, 2, "quad4")
    with pytest.raises(ModelError, match="membrane"):
        assemble(free_model(nodes, conn, "quad4", ShellProperty(E=-1.0, nu=0.3, rho=1.0, t=1e-3)))
    arrowhead = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.2, 0.2, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(ModelError, match=r"quad4 cells \[0\] are not convex"):
        assemble(free_model(arrowhead, [[0, 1, 2, 3]], "quad4"))
    collapsed = nodes.copy()
    collapsed[conn[0, 2]] = collapsed[conn[0, 0]]
    with pytest.raises(ModelError, match=r"shell cells \[0\] are degenerate"):
        assemble(free_model(collapsed, conn, "quad4"))


def linear_states(nodes):
    """Exact nodal DOFs (6 n) of two patch-test states on the plate z = 0: a constant membrane
    strain with a rigid in-plane rotation, and a constant bending curvature (Kirchhoff slopes).
    Returns the two states as columns."""
    x, y = nodes[:, 0], nodes[:, 1]
    n = len(nodes)
    mem = np.zeros((n, 6))
    mem[:, 0] = 1e-3 * x + 4e-4 * y
    mem[:, 1] = -2e-4 * x - 3e-4 * y
    mem[:, 5] = 0.5 * (-2e-4 - 4e-4)  # theta_z = (v,x - u,y) / 2
    bend = np.zeros((n, 6))
    a, b, c = 0.3, -0.2, 0.15  # w = (a x^2 + b y^2 + c x y) / 2
    bend[:, 2] = 0.5 * (a * x**2 + b * y**2 + c * x * y)
    bend[:, 3] = b * y + 0.5 * c * x  # theta_x = w,y
    bend[:, 4] = -(a * x + 0.5 * c * y)  # theta_y = -w,x
    return np.column_stack([mem.ravel(), bend.ravel()])


@pytest.mark.parametrize("kind", KINDS)
def test_patch_test_constant_strain_and_curvature_on_irregular_mesh(kind):
    """Prescribe an exact constant-strain (membrane) or constant-curvature (bending) state on
    the boundary of an irregular mesh; the interior nodes must reproduce it (no loads)."""
    nodes, conn = distorted_plate(kind, seed=5)
    K, _ = assemble(free_model(nodes, conn, kind))
    on_edge = (np.isclose(nodes[:, 0], 0) | np.isclose(nodes[:, 0], 0.3)
               | np.isclose(nodes[:, 1], 0) | np.isclose(nodes[:, 1], 0.2))
    bdof = (6 * np.flatnonzero(on_edge)[:, None] + np.arange(6)).ravel()
    idof = np.setdiff1d(np.arange(K.shape[0]), bdof)
    K = K.tocsr()
    exact = linear_states(nodes)
    for col in range(exact.shape[1]):
        u = exact[:, col]
        ui = spsolve(K[idof][:, idof].tocsc(), -K[idof][:, bdof] @ u[bdof])
        np.testing.assert_allclose(ui, u[idof], rtol=0, atol=1e-7 * np.abs(u).max())  # round-off: cond(K) ~ 1e8


def test_slightly_warped_quads_keep_rigid_modes_and_agree_with_flat_triangles():
    """A hyperbolic-paraboloid panel (doubly curved; each quad warped by ~1 % of its size from its
    mean plane): the quad mesh still floats with exactly six rigid modes (rigid-link warping
    correction), and its first frequencies match the same surface cut into flat triangles."""
    results = []
    for kind in KINDS:
        nodes, conn = rectangle(0.3, 0.2, 12, 8, kind)
        nodes[:, 2] = (nodes[:, 0] - 0.15) * (nodes[:, 1] - 0.1) / 3.0
        modes = solve_modes(free_model(placed(nodes, seed=2), conn, kind), n_modes=4)
        assert modes.n_rigid == 6
        results.append(modes.frequencies)
    np.testing.assert_allclose(results[0], results[1], rtol=2e-2)
