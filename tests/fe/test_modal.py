"""solve_modes against closed-form spring-mass chains (dense and sparse paths), the thesis' 10-DOF
string (Table 5.5), rigid-body detection and the errors for under-constrained models."""

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla

from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle
from pcbdyn.fe.modal import DENSE_MAX, reduced_system, solve_modes, uncoupled_blocks
from pcbdyn.fe.model import Model, ModelError
from pcbdyn.fe.properties import BeamProperty, MassProperty, ShellProperty, SpringProperty

REF = Path("/work/shared/reference/thesis_tables.json")


def chain(ks, ms, wall=True, axes=(0,)):
    """wall-k1-m1-k2-m2-...: node 0 is the wall, node i carries mass m_i; springs act along ``axes``
    (each axis an independent identical chain), every other DOF is fixed."""
    n = len(ms)
    nodes = np.zeros((n + 1, 3))
    nodes[:, 0] = np.arange(n + 1)
    model = Model(nodes)
    for i, k in enumerate(ks):
        kk = np.zeros(6)
        kk[list(axes)] = k
        model.add(f"k{i + 1}", "spring", [[i, i + 1]], SpringProperty(tuple(kk)))
    for i, m in enumerate(ms):
        model.add(f"m{i + 1}", "mass", [[i + 1]], MassProperty(float(m)))
    model.fix(np.arange(n + 1), [d for d in range(6) if d not in axes])
    if wall:
        model.fix(0)
    return model


def chain_matrices(ks, ms):
    """The hand-built fixed-free chain matrices (n x n)."""
    n = len(ms)
    K = np.zeros((n, n))
    for i, k in enumerate(ks):
        K[i, i] += k
        if i > 0:
            K[i - 1, i - 1] += k
            K[i - 1, i] -= k
            K[i, i - 1] -= k
    return K, np.diag(ms)


@pytest.fixture(scope="module")
def string_case():
    return json.loads(REF.read_text())["cases"]["T5.5_string_10dof"]


@pytest.mark.parametrize("variant", [("k_pa_MN_per_m", "m_pa_kg", "fa_Hz"), ("k_px_MN_per_m", "m_px_kg", "fx_Hz")])
def test_thesis_string_frequencies_and_mass_normalisation(string_case, variant):
    kname, mname, fname = variant
    ks = np.array(string_case["inputs"][kname]) * 1e6
    ms = np.array(string_case["inputs"][mname])
    model = chain(ks, ms)
    modes = solve_modes(model, n_modes=10)
    Kh, Mh = chain_matrices(ks, ms)
    lam = sla.eigh(Kh, Mh, eigvals_only=True)
    np.testing.assert_allclose(modes.omega2, lam, rtol=1e-9)
    ref = np.array(string_case["ours"][fname])
    np.testing.assert_array_equal(np.round(modes.frequencies, 4), np.round(ref, 4))
    assert modes.n_rigid == 0
    _, M = assemble(model)
    np.testing.assert_allclose(modes.shapes.T @ (M @ modes.shapes), np.eye(10), atol=1e-10)
    # the shapes are eigenvectors of the hand-built pencil: K phi = w^2 M phi on the ux DOFs
    phi = modes.shapes[6 * np.arange(1, 11)]
    np.testing.assert_allclose(Kh @ phi, Mh @ phi * modes.omega2, atol=1e-6 * np.abs(Kh @ phi).max())


def test_f_max_and_more_modes_than_dofs(string_case):
    ks = np.array(string_case["inputs"]["k_pa_MN_per_m"]) * 1e6
    ms = np.array(string_case["inputs"]["m_pa_kg"])
    model = chain(ks, ms)
    all10 = solve_modes(model, n_modes=10).frequencies
    below = solve_modes(model, f_max=200.0).frequencies
    assert below.size == string_case["ours"]["n_modes_below_200Hz"]["fa"]
    np.testing.assert_allclose(below, all10[all10 <= 200.0], rtol=1e-12)
    capped = solve_modes(model, n_modes=50)
    np.testing.assert_allclose(capped.frequencies, all10, rtol=1e-12)


def uniform_fixed_free(n, k, m):
    r = np.arange(1, n + 1)
    return 2.0 * np.sqrt(k / m) * np.sin((2 * r - 1) * np.pi / (2 * (2 * n + 1)))


def test_sparse_path_long_chain_with_f_max_growth():
    """A 1500-mass uniform chain (beyond the dense limit) against its closed-form spectrum; f_max
    needs more modes than the first eigsh request, so the request has to grow."""
    n, k, m = 1500, 1e6, 0.5
    assert n > DENSE_MAX
    w = uniform_fixed_free(n, k, m)
    f_exact = w / (2 * np.pi)
    f_max = 0.5 * (f_exact[44] + f_exact[45])
    modes = solve_modes(chain([k] * n, [m] * n), f_max=f_max)
    assert modes.frequencies.size == 45
    np.testing.assert_allclose(modes.frequencies, f_exact[:45], rtol=1e-9)


def test_repeated_eigenvalues_sparse():
    """A free ring of 1000 equal masses (one connected block, sparse path): one rigid mode and every
    elastic frequency 2 sqrt(k/m) sin(pi r / n) twice; both copies found, shapes M-orthonormal."""
    n, k, m = 1000, 2e5, 0.1
    assert n > DENSE_MAX
    model = chain_free(n, k, m)
    model.add("closure", "spring", [[n - 1, 0]], SpringProperty((k, 0, 0, 0, 0, 0)))
    model.free = True
    modes = solve_modes(model, n_modes=12)
    assert modes.n_rigid == 1
    f = 2 * np.sqrt(k / m) * np.sin(np.pi * np.arange(1, 7) / n) / (2 * np.pi)
    np.testing.assert_allclose(modes.frequencies, np.repeat(f, 2), rtol=1e-9)
    _, M = assemble(model)
    np.testing.assert_allclose(modes.shapes.T @ (M @ modes.shapes), np.eye(12), atol=1e-10)


def test_uncoupled_blocks_are_solved_apart():
    """Two independent chains (x and y DOFs, different stiffness): the blocks are found and the
    merged spectrum is the sorted union of both closed-form spectra, whatever block holds a mode."""
    n, m = 700, 0.1
    model = chain([1e5] * n, [m] * n, axes=(0, 1))
    model.sets = {name: es for name, es in model.sets.items() if not name.startswith("k")}
    model.add("kx", "spring", np.c_[np.arange(n), np.arange(1, n + 1)], SpringProperty((1e5, 0, 0, 0, 0, 0)))
    model.add("ky", "spring", np.c_[np.arange(n), np.arange(1, n + 1)], SpringProperty((0, 1.7e5, 0, 0, 0, 0)))
    red, Kr, Mr = reduced_system(model)
    blocks = uncoupled_blocks(Kr, Mr)
    assert [b.size for b in blocks] == [n, n]
    f = np.sort(np.r_[uniform_fixed_free(n, 1e5, m), uniform_fixed_free(n, 1.7e5, m)])[:15] / (2 * np.pi)
    np.testing.assert_allclose(solve_modes(model, n_modes=15).frequencies, f, rtol=1e-9)
    f_max = 0.5 * (f[9] + f[10])
    np.testing.assert_allclose(solve_modes(model, f_max=f_max).frequencies, f[:10], rtol=1e-9)


@pytest.mark.parametrize("n", [10, 1200])
def test_free_chain_has_one_rigid_mode(n):
    """Free uniform chain: w_r = 2 sqrt(k/m) sin(r pi / 2n), r = 0 (rigid) .. n-1; dense and sparse."""
    k, m = 1e5, 0.2
    model = chain_free(n, k, m)
    model.free = True
    modes = solve_modes(model, n_modes=8)
    assert modes.n_rigid == 1
    r = np.arange(1, 9)
    np.testing.assert_allclose(modes.frequencies, 2 * np.sqrt(k / m) * np.sin(r * np.pi / (2 * n)) / (2 * np.pi), rtol=1e-9)
    rig = modes.rigid_shapes[6 * np.arange(n)]
    np.testing.assert_allclose(np.abs(rig[:, 0]), 1.0 / np.sqrt(n * m), rtol=1e-8)  # uniform translation


def chain_free(n, k, m):
    """n equal masses on nodes 0..n-1 joined by n-1 equal springs along x, nothing fixed in x."""
    nodes = np.zeros((n, 3))
    nodes[:, 0] = np.arange(n)
    model = Model(nodes)
    model.add("k", "spring", np.c_[np.arange(n - 1), np.arange(1, n)], SpringProperty((k, 0, 0, 0, 0, 0)))
    model.add("m", "mass", np.arange(n)[:, None], MassProperty(m))
    model.fix(np.arange(n), [1, 2, 3, 4, 5])
    return model


def test_free_translational_network_has_three_rigid_modes():
    """Point masses (no rotary inertia) at the corners of a cube, joined by x/y/z springs: only the
    three translations are strain-free (a rotation stretches the axis-aligned springs)."""
    nodes = np.array([[i, j, kk] for i in (0, 1) for j in (0, 1) for kk in (0, 1)], dtype=float) * 0.1
    model = Model(nodes)
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(np.abs(nodes[a] - nodes[b])) < 0.15]
    model.add("k", "spring", edges, SpringProperty((3e4, 5e4, 7e4, 0, 0, 0)))
    model.add("m", "mass", np.arange(8)[:, None], MassProperty(0.05))
    model.free = True
    modes = solve_modes(model, n_modes=30)
    assert modes.n_rigid == 3
    assert modes.frequencies.size == 8 * 3 - 3
    _, M = assemble(model)
    total = modes.rigid_shapes.T @ (M @ modes.rigid_shapes)
    np.testing.assert_allclose(total, np.eye(3), atol=1e-10)


def beam_frame():
    """A free, non-planar frame of three steel tubes with rotary inertia: six rigid-body modes."""
    nodes = np.array([[0, 0, 0], [0.2, 0, 0], [0.2, 0.15, 0], [0.2, 0.15, 0.1]], dtype=float)
    n_el = 4
    pts, conn = [nodes[0]], []
    for a, b in zip(nodes[:-1], nodes[1:]):
        for t in np.linspace(0, 1, n_el + 1)[1:]:
            pts.append(a + t * (b - a))
            conn.append([len(pts) - 2, len(pts) - 1])
    model = Model(np.array(pts))
    conn = np.array(conn)
    props = [
        BeamProperty(210e9, 0.3, 7850, 1e-4, 2e-9, 3e-9, 4e-9, orientation=(0, 0, 1)),
        BeamProperty(70e9, 0.33, 2700, 2e-4, 4e-9, 1e-9, 3e-9, orientation=(0, 0, 1)),
        BeamProperty(210e9, 0.3, 7850, 1.5e-4, 3e-9, 3e-9, 5e-9, orientation=(1, 0, 0)),
    ]
    for i, p in enumerate(props):
        model.add(f"b{i}", "beam2", conn[i * n_el:(i + 1) * n_el], p)
    return model


def test_free_beam_frame_has_six_rigid_modes():
    model = beam_frame()
    model.free = True
    modes = solve_modes(model, n_modes=5)
    assert modes.n_rigid == 6
    assert modes.frequencies[0] > 1.0  # the first elastic mode is well away from zero
    K, M = assemble(model)
    np.testing.assert_allclose(modes.rigid_shapes.T @ (M @ modes.rigid_shapes), np.eye(6), atol=1e-10)
    # rigid shapes carry no strain energy
    assert np.abs(modes.rigid_shapes.T @ (K @ modes.rigid_shapes)).max() < 1e-8 * modes.omega2[0]


def test_under_constrained_model_not_declared_free_raises():
    model = chain_free(6, 1e4, 0.1)
    with pytest.raises(ModelError, match="not declared free.*node .* ux.*model.free = True"):
        solve_modes(model)
    frame = beam_frame()
    frame.fix(0, ["ux", "uy", "uz"])  # pinned at one point: three rotations remain
    with pytest.raises(ModelError, match="3 zero-frequency"):
        solve_modes(frame)
    frame.fix(frame.n_nodes - 1)  # clamped at the far end too: now properly supported
    assert solve_modes(frame, n_modes=3).frequencies[0] > 0


def test_disconnected_mass_is_reported_by_node():
    """A mass on a spring-less node (a forgotten connection) names that node in the error."""
    model = chain([1e4] * 3, [0.1] * 3)
    extra = model.add_nodes([[5.0, 0, 0]])
    model.add("loose", "mass", extra[:, None], MassProperty(0.2))
    model.fix(extra, [1, 2, 3, 4, 5])
    with pytest.raises(ModelError, match=f"node {extra[0]} ux"):
        solve_modes(model)


def test_bad_arguments():
    model = chain([1e4] * 3, [0.1] * 3)
    with pytest.raises(ValueError, match="n_modes"):
        solve_modes(model, n_modes=0)
    with pytest.raises(ValueError, match="f_max"):
        solve_modes(model, f_max=-5.0)


def _square_plate(n, tilt):
    """A free 0.2 m square steel plate, 2 mm thick, n x n quads, rotated out of plane by ``tilt``."""
    nodes, quads = rectangle(0.2, 0.2, n, n)
    c, s = np.cos(tilt), np.sin(tilt)
    nodes = nodes @ np.array([[1, 0, 0], [0, c, s], [0, -s, c]]) @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(E=210e9, nu=0.3, rho=7850.0, t=2e-3))
    model.free = True
    return model


def test_flat_plate_blocks_match_tilted_plate():
    """A flat plate splits into bending and membrane blocks solved apart; the same plate tilted in
    3-D is one coupled block. Both give six rigid-body modes and the same elastic frequencies."""
    pytest.importorskip("pcbdyn.fe.elements.shell_quad4")
    flat, tilted = _square_plate(20, 0.0), _square_plate(20, 0.6)
    _, Kr, Mr = reduced_system(flat)
    assert len(uncoupled_blocks(Kr, Mr)) == 2
    _, Kt, Mt = reduced_system(tilted)
    assert len(uncoupled_blocks(Kt, Mt)) == 1
    a, b = solve_modes(flat, n_modes=12), solve_modes(tilted, n_modes=12)
    assert a.n_rigid == b.n_rigid == 6
    np.testing.assert_allclose(a.frequencies, b.frequencies, rtol=1e-8)


def test_massless_mechanism_is_an_error():
    """Two massless nodes joined by an x spring and nothing else: K + sM is singular for every s."""
    model = Model([[0.0, 0, 0], [1.0, 0, 0]])
    model.add("k", "spring", [[0, 1]], SpringProperty((1e3, 0, 0, 0, 0, 0)))
    model.free = True
    with pytest.raises(ModelError, match="massless mechanism"):
        solve_modes(model)
