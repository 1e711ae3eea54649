"""Distributed edge springs, discrete springs and point masses."""

import numpy as np
import pytest
import scipy.linalg as sla

from pcbdyn.fe import BeamProperty, EdgeSpringProperty, MassProperty, Model, ModelError, SpringProperty
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.elements.edge_spring import edge_frame, matrices as edge_matrices
from pcbdyn.fe.modal import solve_modes

K_EDGE = (1.0e5, 2.0e5, 3.0e5, 40.0, 50.0, 60.0)  # N/m/m and N m/rad/m


def _rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _edge_cell(Q, L=0.037):
    """One edge of length L along Q's first column, with the shell normal along Q's third column."""
    xyz = np.array([[[0.1, -0.2, 0.3], [0.1, -0.2, 0.3]]])
    xyz[0, 1] += L * Q[:, 0]
    return xyz, EdgeSpringProperty(k=K_EDGE, normal=tuple(Q[:, 2] + 0.3 * Q[:, 0]))  # normal need not be exact


@pytest.mark.parametrize("seed", [None, 1, 2])
def test_edge_spring_uniform_motion_gives_k_times_length(seed):
    """A uniform unit motion along edge axis i (translation, then rotation) is resisted by k_i * L in
    total, half at each node, in the edge's own frame whatever its direction in space."""
    Q = np.eye(3) if seed is None else _rotation(seed)
    L = 0.037
    xyz, p = _edge_cell(Q, L)
    K, M = edge_matrices(xyz, p)
    assert not M.any()
    _, R = edge_frame(xyz, p.normal)
    assert np.allclose(R[0], Q.T, atol=1e-12)
    for i in range(6):
        a = np.zeros(6)
        a[i // 3 * 3 : i // 3 * 3 + 3] = Q[:, i % 3]  # unit motion along edge axis i % 3
        f = (K[0] @ np.tile(a, 2)).reshape(2, 6)
        expected = np.zeros(6)
        expected[i // 3 * 3 : i // 3 * 3 + 3] = K_EDGE[i] * L / 2 * Q[:, i % 3]
        assert np.allclose(f, expected[None, :], rtol=0, atol=1e-9 * K_EDGE[i] * L)


def test_edge_spring_linear_motion_is_integrated_exactly():
    """Normal displacement rising linearly from 0 to 1 along the edge: the distributed load k3 s / L
    has consistent nodal forces k3 L / 6 and k3 L / 3 (a tributary-length lumping would give 0 and
    k3 L / 2)."""
    L = 0.05
    xyz, p = _edge_cell(np.eye(3), L)
    K, _ = edge_matrices(xyz, p)
    u = np.zeros(12)
    u[6 + 2] = 1.0
    f = K[0] @ u
    assert f[2] == pytest.approx(K_EDGE[2] * L / 6, rel=1e-12)
    assert f[6 + 2] == pytest.approx(K_EDGE[2] * L / 3, rel=1e-12)
    assert np.allclose(np.delete(f, [2, 8]), 0.0, atol=1e-9)


def test_edge_spring_bad_input():
    xyz = np.array([[[0.0, 0, 0], [1.0, 0, 0]]])
    with pytest.raises(ModelError, match="normal"):
        edge_matrices(xyz, EdgeSpringProperty(k=K_EDGE, normal=(1.0, 0.0, 0.0)))
    with pytest.raises(ModelError, match="k must be six"):
        edge_matrices(xyz, EdgeSpringProperty(k=(1.0, 2.0)))


def _beam_on_foundation(n_el, L, E, rho, b, h, kf):
    x = np.linspace(0, L, n_el + 1)
    model = Model(np.column_stack([x, 0 * x, 0 * x]))
    conn = np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)])
    model.add("beam", "beam2", conn, BeamProperty(E=E, nu=0.3, rho=rho, A=b * h, Iy=b * h**3 / 12,
                                                   Iz=b**3 * h / 12, J=b * h**3 / 3, orientation=(0.0, 1.0, 0.0),
                                                   rotary_inertia=False))
    model.add("bed", "edge_spring", conn, EdgeSpringProperty(k=(0.0, 0.0, kf, 0.0, 0.0, 0.0), normal=(0, 0, 1)))
    model.fix(np.arange(n_el + 1), ["ux", "uy", "rx", "rz"])
    model.fix([0, n_el], ["uz"])
    return solve_modes(model, n_modes=3).frequencies


def test_beam_on_edge_spring_foundation():
    """A simply supported beam resting on a Winkler foundation k3 [N/m/m] made of edge springs:
    omega^2 = (EI (n pi / L)^4 + k3) / (rho A). The springs see the linear interpolation of w between
    nodes (as along a shell edge), not the beam's cubic, so the foundation energy converges as h^2."""
    L, b, h, E, rho = 0.4, 0.01, 0.002, 70e9, 2700.0
    A, I = b * h, b * h**3 / 12
    kf = 2.0e6
    n = np.arange(1, 4)
    exact = np.sqrt((E * I * (n * np.pi / L) ** 4 + kf) / (rho * A)) / (2 * np.pi)
    assert exact[0] > 1.5 * np.pi / (2 * L**2) * np.sqrt(E * I / (rho * A))  # the foundation matters
    err40 = np.abs(_beam_on_foundation(40, L, E, rho, b, h, kf) / exact - 1)
    err80 = np.abs(_beam_on_foundation(80, L, E, rho, b, h, kf) / exact - 1)
    assert err40.max() < 5e-3 and err80.max() < 1.2e-3
    assert np.all((3.5 < err40 / err80) & (err40 / err80 < 4.5))


def _dense_frequencies(model):
    K, M = assemble(model)
    w2 = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    return np.sqrt(np.abs(w2)) / (2 * np.pi)


def test_point_mass_on_ground_springs():
    k = (1e4, 2e4, 3e4, 5.0, 6.0, 7.0)
    J = (1e-4, 2e-4, 3e-4)
    model = Model([[0.0, 0.0, 0.0]])
    model.add("s", "spring", [[0]], SpringProperty(k=k))
    model.add("m", "mass", [[0]], MassProperty(0.5, J))
    f = _dense_frequencies(model)
    exact = np.sqrt(np.array(k) / np.array([0.5] * 3 + list(J))) / (2 * np.pi)
    assert np.allclose(np.sort(f), np.sort(exact), rtol=1e-12)


def test_full_spring_matrix_in_a_rotated_frame():
    """A 6x6 spring matrix given in a rotated frame (Q diag(k) Q^T per block) between two masses gives the
    diagonal spring's frequencies sqrt(k (1/m1 + 1/m2))."""
    Q = _rotation(7)
    kt, kr = np.array([1e4, 3e4, 5e4]), np.array([2.0, 4.0, 6.0])
    k6 = np.zeros((6, 6))
    k6[:3, :3] = Q @ np.diag(kt) @ Q.T
    k6[3:, 3:] = Q @ np.diag(kr) @ Q.T
    model = Model([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]])
    model.add("s", "spring", [[0, 1]], SpringProperty(k=tuple(map(tuple, k6))))
    model.add("m1", "mass", [[0]], MassProperty(0.2, (1e-5, 1e-5, 1e-5)))
    model.add("m2", "mass", [[1]], MassProperty(0.3, (2e-5, 2e-5, 2e-5)))
    f = np.sort(_dense_frequencies(model))
    assert np.allclose(f[:6], 0.0, atol=1e-6 * f[-1])  # the pair floats: six rigid-body modes
    exact = np.sqrt(np.concatenate([kt * (1 / 0.2 + 1 / 0.3), kr * (1 / 1e-5 + 1 / 2e-5)])) / (2 * np.pi)
    assert np.allclose(f[6:], np.sort(exact), rtol=1e-9)


@pytest.mark.parametrize("at", [(0.0237, 0.0461), (0.05, 0.04), (0.0925, 0.0035)])
def test_spring_at_a_point_between_nodes_carries_a_stiff_plate_as_a_rigid_body(at):
    """A stiff free plate (steel, 100 x 80 x 5 mm) on one soft spring to ground at a point between
    nodes (the shape functions of the cell holding it as weights): its one nonzero rigid-body
    eigenvalue is k |u|^2 (less by the plate's elasticity), u the mass-normalised rigid-body modes'
    deflection at the point itself (a node 1.2 mm away would change it by up to 5 %), and a rigid block's
    k (1/m + dx^2 / I_y + dy^2 / I_x), I = m (side^2 + t^2) / 12, to within the plate's elasticity."""
    from pcbdyn.fe.generate import rectangle
    from pcbdyn.fe.probe import model_probe
    from pcbdyn.fe.properties import ShellProperty

    a, b, t, rho, k = 0.1, 0.08, 5e-3, 7800.0, 1e3
    nodes, quads = rectangle(a, b, 8, 8)
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(t=t, E=2.1e11, nu=0.3, rho=rho))
    model.free = True
    probe = model_probe(model, [[at[0], at[1], 0.0]])
    u = np.ravel(probe.P @ solve_modes(model, n_modes=1).rigid_shapes)
    loc = probe.location
    model.add("s", "spring", loc.nodes, SpringProperty(k=(0.0, 0.0, k, 0.0, 0.0, 0.0), weights=tuple(loc.weights[0])))
    modes = solve_modes(model, n_modes=1)
    m = rho * a * b * t
    dx, dy = at[0] - a / 2, at[1] - b / 2
    rigid_block = k * (1 / m + dx**2 / (m * (a**2 + t**2) / 12) + dy**2 / (m * (b**2 + t**2) / 12))
    assert modes.n_rigid == 5
    ritz = k * float(u @ u)  # the rigid-body modes alone: an upper bound, the plate's elasticity lowers it a little
    assert ritz * (1 - 5e-4) <= modes.omega2[0] <= ritz * (1 + 1e-9)
    assert modes.omega2[0] == pytest.approx(rigid_block, rel=3e-3)


def test_spring_at_a_point_needs_a_weight_per_node():
    model = Model([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]])
    with pytest.raises(ModelError, match="one weight per node"):
        model.add("s", "spring", [[0, 1, 2]], SpringProperty(k=(0.0, 0.0, 1e3, 0.0, 0.0, 0.0), weights=(0.5, 0.5)))


def test_spring_and_mass_bad_input():
    model = Model([[0.0, 0.0, 0.0]])
    asym = np.eye(6)
    asym[0, 1] = 1.0
    model.add("s", "spring", [[0]], SpringProperty(k=tuple(map(tuple, asym))))
    with pytest.raises(ModelError, match="SpringProperty.k"):
        assemble(model)
    model = Model([[0.0, 0.0, 0.0]])
    model.add("m", "mass", [[0]], MassProperty(-1.0))
    with pytest.raises(ModelError, match="MassProperty"):
        assemble(model)


@pytest.mark.parametrize("seed,sampled", [(None, False), (3, False), (4, True)])
def test_footprint_mass_moves_with_the_rigid_motion_of_its_nodes(seed, sampled):
    """A mass cell over a footprint, sampled at its nodes (the body at the first node) or at points
    interpolated from them (weights summing to 1; the body at the first point, between nodes),
    carries exactly m under any rigid translation and J about each axis under a rigid rotation
    about the body's point, whatever the footprint's orientation in space; a motion of the nodes
    with no rigid part carries none."""
    Q = np.eye(3) if seed is None else _rotation(seed)
    local = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [-0.004, 0.009, 0.0], [0.003, -0.008, 0.0], [-0.01, -0.002, 0.0]])
    x0 = np.array([0.2, -0.1, 0.05])
    model = Model(x0 + local @ Q.T)
    J = (2.0e-6, 3.0e-6, 1.0e-6)
    Jg = Q @ np.diag(J) @ Q.T  # the body's inertia in global axes
    W = None
    if sampled:
        W = np.random.default_rng(seed).random((9, 5))
        W /= W.sum(axis=1, keepdims=True)
    model.add("body", "mass", [list(range(5))], MassProperty(0.05, Jg, footprint=W))
    _, M = assemble(model)
    M = M.toarray()
    r = model.nodes - (x0 if W is None else W[0] @ model.nodes)
    for a in range(3):
        t = np.zeros((5, 6))
        t[:, a] = 1.0
        assert t.ravel() @ M @ t.ravel() == pytest.approx(0.05, rel=1e-10)
        axis = Q[:, a]
        rot = np.zeros((5, 6))
        rot[:, :3] = np.cross(axis, r)
        rot[:, 3:] = axis  # the nodes' own rotations carry nothing: the body follows their translations
        assert rot.ravel() @ M @ rot.ravel() == pytest.approx(J[a], rel=1e-10)
    rigid = np.column_stack([np.concatenate([np.eye(3)[a]] * 5) for a in range(3)]
                            + [np.cross(Q[:, a], r).ravel() for a in range(3)])  # (15, 6)
    u = np.random.default_rng(7).normal(size=15)
    u -= rigid @ np.linalg.lstsq(rigid, u, rcond=None)[0]
    deform = np.zeros((5, 6))
    deform[:, :3] = u.reshape(5, 3)
    if not sampled:  # sample points between the nodes see part of a deformation as rigid motion
        assert abs(deform.ravel() @ M @ deform.ravel()) < 1e-12 * 0.05 * (u @ u)
    with pytest.raises(ModelError, match="footprint of 3"):
        Model(model.nodes).add("body", "mass", [[0, 1]], MassProperty(0.05))
