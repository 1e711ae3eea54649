"""solve_modes against closed-form spring-mass chains (dense and sparse paths), the thesis' 10-DOF
string (Table 5.5), rigid-body detection and the errors for under-constrained models."""


import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle
from pcbdyn.fe.modal import DENSE_MAX, reduced_system, solve_modes, uncoupled_blocks
from pcbdyn.fe.model import Model, ModelError
from pcbdyn.fe.properties import BeamProperty, MassProperty, ShellProperty, SpringProperty

from reference import thesis_case

from frames import three_member_frame


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
    return thesis_case("T5.5_string_10dof")


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
    holds more modes than a default request of 20, all of which must be found."""
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
    """A free, non-planar frame of three steel and aluminium tubes with rotary inertia: six rigid-body modes."""
    return three_member_frame([[0, 0, 0], [0.2, 0, 0], [0.2, 0.15, 0], [0.2, 0.15, 0.1]], 4)


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


def _pencil_count(Kr, Mr, lam):
    """Eigenvalues of the pencil (K, M) below ``lam``, from dense LAPACK."""
    return int(np.sum(sla.eigh(Kr.toarray(), Mr.toarray(), eigvals_only=True) < lam))


@pytest.mark.parametrize("fallback", [False, True])
def test_sturm_count_matches_dense_spectrum(monkeypatch, fallback):
    """The number of negative LDL^T pivots of K - s M equals the number of pencil eigenvalues below
    s (Sylvester's law of inertia), with SuperLU and with the CHOLMOD fallback, at shifts below,
    between and above the fixed-free chain's eigenvalues."""
    from pcbdyn.fe import linsolve

    if fallback:
        if linsolve.cholesky is None:
            pytest.skip("scikit-sparse (CHOLMOD) is not installed")
        monkeypatch.setattr(linsolve, "_superlu_pivots", lambda L: None)
    n = 80
    Kd, Md = chain_matrices(np.linspace(1e4, 3e4, n), np.linspace(0.1, 0.3, n))
    lam = sla.eigh(Kd, Md, eigvals_only=True)
    K, M = sp.csc_matrix(Kd), sp.csc_matrix(Md)
    for s in (0.5 * lam[0], 0.5 * (lam[9] + lam[10]), 0.5 * (lam[40] + lam[41]), 2 * lam[-1]):
        expected = int(np.sum(lam < s))
        assert linsolve.negative_eigenvalue_count(K - s * M) == expected
        assert linsolve.has_no_negative_eigenvalue(K - s * M) == (expected == 0)


def test_free_flat_plate_membrane_block_asks_only_its_modes_below_the_cut(monkeypatch):
    """A free flat plate: the membrane block has exactly its three in-plane rigid modes below the
    n-th bending frequency, so eigsh is asked for exactly three there (not for elastic membrane
    modes, which may sit in a tight cluster of drilling modes). Frequencies, rigid-mode count and
    M-orthonormality agree with a dense solve of the whole pencil, for n_modes and for f_max."""
    pytest.importorskip("pcbdyn.fe.elements.shell_quad4")
    model = _square_plate(14, 0.0)
    red, Kr, Mr = reduced_system(model)
    blocks = uncoupled_blocks(Kr, Mr)
    assert len(blocks) == 2 and min(b.size for b in blocks) > DENSE_MAX
    lam = sla.eigh(Kr.toarray(), Mr.toarray(), eigvals_only=True)
    f_ref = np.sqrt(lam[6:]) / (2 * np.pi)
    asked = eigsh_requests(monkeypatch)
    modes = solve_modes(model, n_modes=10)
    assert modes.n_rigid == 6
    np.testing.assert_allclose(modes.frequencies, f_ref[:10], rtol=1e-8)
    assert asked == [16, 3]  # bending: 10 elastic + 6 possibly rigid; membrane: its 3 rigid modes
    _, M = assemble(model)
    np.testing.assert_allclose(modes.shapes.T @ (M @ modes.shapes), np.eye(10), atol=1e-10)
    f_max = 0.5 * (f_ref[13] + f_ref[14])
    np.testing.assert_allclose(solve_modes(model, f_max=f_max).frequencies, f_ref[:14], rtol=1e-8)


def test_clamped_block_with_nothing_below_the_cut_is_skipped(monkeypatch):
    """A clamped flat plate's membrane block has no eigenvalue below its 8th bending one: a Cholesky
    of K - s M proves it, so eigsh runs on the bending block only; the frequencies match a dense
    solve of the whole pencil."""
    pytest.importorskip("pcbdyn.fe.elements.shell_quad4")
    nodes, quads = rectangle(0.2, 0.2, 16, 16)
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(E=210e9, nu=0.3, rho=7850.0, t=2e-3))
    on_edge = np.isclose(nodes[:, :2], 0).any(axis=1) | np.isclose(nodes[:, :2], 0.2).any(axis=1)
    model.fix(np.flatnonzero(on_edge))
    _, Kr, Mr = reduced_system(model)
    assert [b.size > DENSE_MAX for b in uncoupled_blocks(Kr, Mr)] == [True, True]
    lam = sla.eigh(Kr.toarray(), Mr.toarray(), eigvals_only=True)
    asked = eigsh_requests(monkeypatch)
    modes = solve_modes(model, n_modes=8)
    np.testing.assert_allclose(modes.omega2, lam[:8], rtol=1e-8)
    assert asked == [8]


@pytest.mark.parametrize("guess", ["bending", "membrane"])
def test_first_solve_starts_with_the_group_moving_along_one_axis(monkeypatch, guess):
    """The first solve of a flat plate's pattern starts with the group that translates along z only
    (bending) without estimating each group's first eigenvalue; told the wrong group (the membrane
    one labelled as moving along one axis), it does more work but finds the same modes: the other
    group is counted below the cut either way. Both agree with a dense solve of the whole pencil."""
    from pcbdyn.fe import blocks, modal

    model = _square_plate(14, 0.0)
    model.free = False
    nodes = model.nodes
    on_edge = np.isclose(nodes[:, :2], 0).any(axis=1) | np.isclose(nodes[:, :2], 0.2).any(axis=1)
    model.fix(np.flatnonzero(on_edge), [0, 1, 2])
    red, Kr, Mr = reduced_system(model)
    lam = sla.eigh(Kr.toarray(), Mr.toarray(), eigvals_only=True)
    axes = np.where(red.independent % 6 < 3, red.independent % 6, -1)
    groups = uncoupled_blocks(Kr, Mr)
    bending = next(g for g, idx in enumerate(groups) if np.all(axes[idx][axes[idx] >= 0] == 2))
    assert modal._bending_group(groups, [False, False], axes) == bending
    if guess == "membrane":
        membrane = groups[1 - bending]
        axes = axes.copy()
        axes[membrane[axes[membrane] >= 0]] = 0
    monkeypatch.setattr(blocks, "_layouts", type(blocks._layouts)())  # a first solve of the pattern
    monkeypatch.setattr(modal._Block, "first_eigenvalue", lambda *a: pytest.fail("estimated the order"))
    out, vec, rigid, _ = modal.solve_pencil(Kr, Mr, n_modes=8, axes=axes)
    assert not rigid.any()
    np.testing.assert_allclose(np.sort(out)[:8], lam[:8], rtol=1e-8)


def test_assembly_equals_sum_of_element_matrices():
    """K and M of a mixed model (quads, beams, springs, masses) equal the plain sum of every element
    matrix at its DOFs (dense reference), with one shared sparsity pattern and int32 indices."""
    pytest.importorskip("pcbdyn.fe.elements.shell_quad4")
    pytest.importorskip("pcbdyn.fe.elements.beam")
    from pcbdyn.fe.assembly import element_matrices
    from pcbdyn.fe.mesh import element_dofs

    nodes, quads = rectangle(0.1, 0.08, 5, 4)
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(E=70e9, nu=0.33, rho=2700.0, t=1e-3))
    model.add("stiffener", "beam2", np.c_[np.arange(5), np.arange(1, 6)],
              BeamProperty(E=70e9, nu=0.33, rho=2700.0, A=1e-5, Iy=1e-11, Iz=2e-11, J=3e-11, orientation=(0, 0, 1)))
    model.add("ground", "spring", [[7, 12]], SpringProperty((1e3, 2e3, 3e3, 4.0, 5.0, 6.0)))
    model.add("lump", "mass", [[9], [20]], MassProperty(0.01))
    K, M = assemble(model)
    Kd, Md = np.zeros(K.shape), np.zeros(K.shape)
    for name, es in model.sets.items():
        Ke, Me = element_matrices(model, name)
        for dofs, ke, me in zip(element_dofs(es.conn), Ke, Me):
            Kd[np.ix_(dofs, dofs)] += ke
            Md[np.ix_(dofs, dofs)] += me
    np.testing.assert_allclose(K.toarray(), Kd, rtol=0, atol=1e-12 * np.abs(Kd).max())
    np.testing.assert_allclose(M.toarray(), Md, rtol=0, atol=1e-12 * np.abs(Md).max())
    assert np.array_equal(K.indptr, M.indptr) and np.array_equal(K.indices, M.indices)
    assert K.has_sorted_indices and K.indices.dtype == np.int32
    sub_K, _ = assemble(model, sets=["stiffener"])
    Kb = np.zeros(K.shape)
    Ke, _ = element_matrices(model, "stiffener")
    for dofs, ke in zip(element_dofs(model.sets["stiffener"].conn), Ke):
        Kb[np.ix_(dofs, dofs)] += ke
    np.testing.assert_allclose(sub_K.toarray(), Kb, rtol=0, atol=1e-12 * np.abs(Kb).max())


def eigsh_requests(monkeypatch) -> list:
    """The number of modes each eigsh call of the modal solver asks for, appended as it runs."""
    import pcbdyn.fe.modal as modal

    asked, eigsh = [], modal.spla.eigsh

    def spy(A, k, **kw):
        asked.append(k)
        return eigsh(A, k=k, **kw)

    monkeypatch.setattr(modal.spla, "eigsh", spy)
    return asked


def test_soft_in_plane_mounts_put_the_membrane_group_first_and_lose_no_mode():
    """A plate simply supported out of plane and held in its plane only by soft corner springs: its
    membrane group's spectrum starts below the bending group's, so the bending-first guess is wrong;
    the membrane modes below the bending cut are still all found (Sturm count), as a dense solve of
    the whole pencil says."""
    pytest.importorskip("pcbdyn.fe.elements.shell_quad4")
    nodes, quads = rectangle(0.2, 0.2, 14, 14)
    corners = [i for i, (x, y, _) in enumerate(nodes) if x in (0.0, 0.2) and y in (0.0, 0.2)]
    model = Model(np.vstack([nodes, nodes[corners]]))
    model.add("plate", "quad4", quads, ShellProperty(E=210e9, nu=0.3, rho=7850.0, t=2e-3))
    anchors = len(nodes) + np.arange(len(corners))
    model.add("mounts", "spring", np.column_stack([corners, anchors]), SpringProperty((2e3, 2e3, 0, 0, 0, 0)))
    model.fix(anchors)
    on_edge = np.isclose(nodes[:, :2], 0).any(axis=1) | np.isclose(nodes[:, :2], 0.2).any(axis=1)
    model.fix(np.flatnonzero(on_edge), [2])
    red, Kr, Mr = reduced_system(model)
    assert len(uncoupled_blocks(Kr, Mr)) == 2
    lam = sla.eigh(Kr.toarray(), Mr.toarray(), eigvals_only=True)
    modes = solve_modes(model, n_modes=8)
    np.testing.assert_allclose(modes.omega2, lam[:8], rtol=1e-6)  # dense round-off: ~1e-16 lam_max on the soft modes
    in_plane = np.abs(modes.shapes[0::6]).max(axis=0) > np.abs(modes.shapes[2::6]).max(axis=0)
    assert in_plane[:3].all()  # the three rigid-like motions on the mounts come first


def test_thick_plate_lowest_modes_are_bending_modes_not_drilling_ones():
    """A clamped square steel plate, 200 x 200 x 10 mm: its in-plane modes start near 15 kHz, far
    above its sixth bending mode (Leissa's lambda = 131.6 against 35.99: about 8 kHz), so its first six
    modes carry their kinetic energy in w and the two bending rotations. The drilling rotation's
    stand-in inertia must not bring spurious modes into that band (with the full rotary inertia
    there, the drilling modes sat at about 5 kHz); the first frequency lies within Mindlin's few %
    below Leissa's Kirchhoff value for t/a = 0.05."""
    pytest.importorskip("pcbdyn.fe.elements.shell_quad4")
    a, t, E, nu, rho = 0.2, 0.01, 210e9, 0.3, 7850.0
    nodes, quads = rectangle(a, a, 16, 16)
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(E=E, nu=nu, rho=rho, t=t))
    model.fix(np.flatnonzero(np.isclose(nodes[:, :2], 0).any(axis=1) | np.isclose(nodes[:, :2], a).any(axis=1)))
    modes = solve_modes(model, n_modes=6)
    _, M = assemble(model)
    bending = np.isin(np.arange(M.shape[0]) % 6, (2, 3, 4))
    phi = modes.shapes
    share = np.einsum("ij,ij->j", phi[bending], (M[bending][:, bending] @ phi[bending])) / \
        np.einsum("ij,ij->j", phi, M @ phi)
    assert share.min() > 0.99
    D = E * t**3 / (12 * (1 - nu**2))
    f_kirchhoff = 35.99 / (2 * np.pi * a**2) * np.sqrt(D / (rho * t))
    assert 0.95 < modes.frequencies[0] / f_kirchhoff < 1.0
