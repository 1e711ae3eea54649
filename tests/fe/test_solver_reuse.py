"""What is kept between solves and what large systems take: the pattern caches (layouts, CHOLMOD
symbolic analyses) give the same modes as a cold solve, the block Lanczos path the same modes as
ARPACK, the kept factorisation the static flexibility, and the index plans the same matrices as
fancy indexing."""

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn.fe import blocks, linsolve, modal, threads
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle, rectangle_edges
from pcbdyn.fe.model import Model
from pcbdyn.fe.properties import ShellProperty, SpringProperty
from pcbdyn.fe.constraints import build_reduction
from pcbdyn.fe.sparsity import Projection, UnionPattern, common_pattern, lower_triangle, same_array, selection


def plate(n, tilt=0.0, support="clamped", aspect=0.93):
    """A 0.16 m plate (a non-square one: no repeated frequencies), n x n quads, tilted out of plane."""
    nodes, quads = rectangle(0.16, 0.16 * aspect, n, n)
    edge = np.unique(np.concatenate(list(rectangle_edges(nodes, 0.16, 0.16 * aspect).values())))
    c, s = np.cos(tilt), np.sin(tilt)
    nodes = nodes @ np.array([[1, 0, 0], [0, c, s], [0, -s, c]]) @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(E=22e9, nu=0.15, rho=1900.0, t=1.6e-3))
    if support == "free":
        model.free = True
    else:
        model.fix(edge, [0, 1, 2] if support == "simple" else None)
    return model


def assert_same_modes(a, b, M):
    np.testing.assert_allclose(a.frequencies, b.frequencies, rtol=1e-9)
    assert a.n_rigid == b.n_rigid
    ab, aa, bb = (np.einsum("ij,ij->j", x, M @ y) for x, y in ((a.shapes, b.shapes), (a.shapes, a.shapes),
                                                               (b.shapes, b.shapes)))
    assert (ab**2 / (aa * bb)).min() > 0.999999


@pytest.fixture
def cold(monkeypatch):
    """Solve as if every pattern were new: no kept layouts or symbolic analyses."""
    monkeypatch.setattr(blocks, "LAYOUT_CACHE_SIZE", 0)
    monkeypatch.setattr(linsolve, "SYMBOLIC_CACHE_SIZE", 0)
    blocks._layouts.clear()
    linsolve.clear_symbolic_cache()


@pytest.fixture
def warm_solves():
    """The plates solved with everything kept, three times on one pattern (other values)."""
    out = {}
    for tilt, support in CASES:
        model = plate(16, tilt, support)
        K, M = assemble(model)
        warm = [modal.solve_modes(model, n_modes=12, K=K * s, M=M * (2 - s)) for s in SCALES]
        analyses = len(linsolve._symbolic)
        assert_same_modes(modal.solve_modes(model, n_modes=12, K=K * 1.1, M=M * 0.9), warm[1], M)
        assert len(linsolve._symbolic) == analyses  # no new symbolic analysis for the same pattern
        out[tilt, support] = model, K, M, warm
    return out


CASES = [(0.0, "free"), (0.0, "clamped"), (0.6, "simple")]
SCALES = (1.0, 1.1, 0.9)


def test_repeated_solves_on_one_pattern_match_cold_solves(warm_solves, cold):
    """Solving again with other values (stiffer, heavier) reuses the layout, the block order and the
    symbolic analysis; the modes equal those of solves that kept nothing."""
    for model, K, M, warm in warm_solves.values():
        for s, w in zip(SCALES, warm):
            assert_same_modes(modal.solve_modes(model, n_modes=12, K=K * s, M=M * (2 - s)), w, M)


def test_cached_block_order_is_the_spectrum_order():
    """After a solve, each group of a flat plate remembers where its elastic spectrum starts: the
    bending group's first frequency exactly, the membrane group's a proven lower bound above it."""
    model = plate(16)
    K, M = assemble(model)
    modes = modal.solve_modes(model, n_modes=8, K=K, M=M)
    _, Kr, Mr = modal.reduced_system(model, K, M)
    lay, _, _ = blocks.layout(Kr, Mr)
    start = np.sort(lay.start)
    np.testing.assert_allclose(start[0], modes.omega2[0], rtol=1e-10)
    assert start[1] >= modes.omega2[-1]


@pytest.mark.parametrize("tilt, support, n_modes, f_max", [(0.0, "free", 10, None), (0.6, "clamped", 20, None),
                                                           (0.6, "free", None, 1500.0), (0.0, "simple", 6, 2000.0)])
def test_block_lanczos_matches_arpack(tilt, support, n_modes, f_max, monkeypatch):
    """Groups above LANCZOS_MIN DOFs go to block Lanczos; forced onto smaller plates (rigid modes,
    f_max, tilted) it finds the modes ARPACK finds."""
    model = plate(18, tilt, support)
    K, M = assemble(model)
    monkeypatch.setattr(modal, "LANCZOS_MIN", 10**9)
    ref = modal.solve_modes(model, n_modes=n_modes, f_max=f_max, K=K, M=M)
    calls = []
    largest = modal.lanczos.largest
    monkeypatch.setattr(modal.lanczos, "largest", lambda *a, **k: calls.append(a[2]) or largest(*a, **k))
    monkeypatch.setattr(modal, "LANCZOS_MIN", 1)
    got = modal.solve_modes(model, n_modes=n_modes, f_max=f_max, K=K, M=M)
    assert calls
    assert_same_modes(got, ref, M)


def test_block_lanczos_repeated_frequencies(monkeypatch):
    """A free ring of 1000 equal masses: every elastic frequency twice and one rigid mode; block
    Lanczos finds both copies (the block holds both directions of each pair)."""
    n, k, m = 1000, 2e5, 0.1
    nodes = np.zeros((n, 3))
    nodes[:, 0] = np.arange(n)
    model = Model(nodes)
    model.add("k", "spring", np.c_[np.arange(n), np.roll(np.arange(n), -1)], SpringProperty((k, 0, 0, 0, 0, 0)))
    model.add("m", "mass", np.arange(n)[:, None], modal_mass(m))
    model.fix(np.arange(n), [1, 2, 3, 4, 5])
    model.free = True
    monkeypatch.setattr(modal, "LANCZOS_MIN", 1)
    modes = modal.solve_modes(model, n_modes=12)
    assert modes.n_rigid == 1
    f = 2 * np.sqrt(k / m) * np.sin(np.pi * np.arange(1, 7) / n) / (2 * np.pi)
    np.testing.assert_allclose(modes.frequencies, np.repeat(f, 2), rtol=1e-9)


def modal_mass(m):
    from pcbdyn.fe.properties import MassProperty

    return MassProperty(m)


@pytest.mark.parametrize("support", ["clamped", "free"])
def test_kept_factorisation_solves_the_shifted_system(support):
    """Modes.shifted applies (K_r - S)^-1, S = blockdiag(sigma_b M_b), with the eigen-solution's
    factors (backward error at round-off); for a constrained model, static() refines it to K_r^-1."""
    model = plate(12, 0.0, support)
    K, M = assemble(model)
    modes = modal.solve_modes(model, n_modes=6, K=K, M=M, keep_factor=True)
    assert modal.solve_modes(model, n_modes=6, K=K, M=M).shifted is None
    _, Kr, Mr = modal.reduced_system(model, K, M)
    S = sp.lil_matrix(Kr.shape)
    for idx, sigma, _ in modes.shifted.groups:
        S[np.ix_(idx, idx)] = sigma * Mr[idx][:, idx]
    f = np.random.default_rng(1).standard_normal((Kr.shape[0], 3))
    x = modes.shifted.solve(f)
    A = (Kr - S.tocsr()).toarray()
    assert np.abs(A @ x - f).max() < 1e-12 * np.abs(A).sum(axis=1).max() * np.abs(x).max()
    if support == "clamped":
        np.testing.assert_allclose(modes.shifted.static(Kr, f), np.linalg.solve(Kr.toarray(), f), rtol=1e-9,
                                   atol=1e-12 * np.abs(x).max())


def test_index_plans_equal_fancy_indexing():
    """Selection (with empty rows at the start, middle and end), lower triangle and common pattern
    give the matrices SciPy's indexing gives."""
    rng = np.random.default_rng(0)
    A = sp.random(40, 40, density=0.15, random_state=1, format="csr")
    keep = sp.diags(np.isin(np.arange(40), [0, 17, 39], invert=True).astype(float))
    A = (keep @ (A + A.T) @ keep).tocsr()  # rows and columns 0, 17, 39 empty
    A.sort_indices()
    idx = np.sort(rng.choice(40, 25, replace=False))
    np.testing.assert_array_equal(selection(A, idx).apply(A.data).toarray(), A[idx][:, idx].toarray())
    L = lower_triangle(A).apply(A.data)
    assert L.format == "csc"
    np.testing.assert_array_equal(L.toarray(), sp.tril(A).toarray())
    B = sp.random(40, 40, density=0.1, random_state=2, format="csr")
    B = (B + B.T).tocsr()
    Kc, Mc = common_pattern(A, B)
    assert same_array(Kc.indices, Mc.indices)
    np.testing.assert_array_equal(Kc.toarray(), A.toarray())
    np.testing.assert_array_equal(Mc.toarray(), B.toarray())


def test_projection_plan_equals_the_triple_product():
    """T^T A T by the kept projection plan equals the sparse triple product to round-off, for a T with
    several masters per slave; K and M on one pattern come out on one pattern, and a Reduction built
    again for the same model reduces on the very index arrays (what the layout cache finds them by)."""
    model = plate(6, support="simple")
    for slave, masters in ((8, (1, 2)), (9, (8,)), (10, (9, 1)), (30, (31, 32, 40))):  # a chain: 10 -> 9 -> 8 -> 1, 2
        model.constrain(6 * slave + 2, [(6 * m + 2, 1.0 / len(masters)) for m in masters])
    K, M = assemble(model)
    red = build_reduction(model, K, M)
    assert not red.is_selection
    for A in (K, M):
        ref = (red.T.T @ A @ red.T).toarray()
        got = Projection.of(A.tocsr(), red.T).apply(A.tocsr().data).toarray()
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-14 * np.abs(ref).max())
    Kr, Mr = red.reduce(K), red.reduce(M)
    again = build_reduction(model, K, M).reduce(M)
    assert same_array(Kr.indices, Mr.indices) and same_array(again.indices, Mr.indices)
    np.testing.assert_array_equal(again.toarray(), Mr.toarray())


def test_a_pattern_covering_a_local_matrix_keeps_its_own_index_arrays():
    """A local matrix (one node's spring) inside a pattern is placed on that pattern itself; one that
    reaches outside it (two far nodes tied) is not covered."""
    K, _ = assemble(plate(4))
    own = UnionPattern.of(K)
    inside = sp.csr_matrix(([1.0], ([3 * 6 + 2], [3 * 6 + 2])), shape=K.shape)
    outside = sp.csr_matrix(([1.0, 1.0], ([2, 20 * 6 + 2], [20 * 6 + 2, 2])), shape=K.shape)
    assert own.covers(inside) and not own.covers(outside)
    assert same_array(own.matrix(K.data).indices, K.indices)
    row = K.indices[K.indptr[20]:K.indptr[21]]
    assert own.positions(inside)[0] == K.indptr[20] + np.flatnonzero(row == 20)[0]


def test_thread_limit_from_the_environment(monkeypatch):
    for name in ("PCBDYN_BLAS_THREADS", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        monkeypatch.delenv(name, raising=False)
    assert threads.thread_limit() == {"blas": 1, "openmp": 1}
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    assert threads.thread_limit() == {"openmp": 1}  # the environment already chose for BLAS
    monkeypatch.setenv("PCBDYN_BLAS_THREADS", "3")
    assert threads.thread_limit() == {"blas": 3, "openmp": 3}
    monkeypatch.setenv("PCBDYN_BLAS_THREADS", "0")
    assert threads.thread_limit() == {}
    monkeypatch.setenv("PCBDYN_BLAS_THREADS", "many")
    with pytest.raises(ValueError, match="PCBDYN_BLAS_THREADS"):
        threads.thread_limit()
