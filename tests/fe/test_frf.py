"""FRFs: modal superposition against direct dynamic-stiffness solution (thesis eq. 3.27-3.29),
single-DOF peaks against their analytical values, the thesis' 10-DOF string receptance H53 and
the residual flexibility of truncated modes."""


import numpy as np
import pytest

from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.frf import frf_direct, frf_modal, residual_flexibility
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.model import Model
from pcbdyn.fe.properties import MassProperty, SpringProperty

from reference import thesis_case


def ux(node):
    return 6 * node


def chain(ks, ms, wall=True):
    """wall(node 0)-k1-m1(node 1)-k2-m2-...; springs and masses act along x only."""
    n = len(ms)
    nodes = np.zeros((n + 1, 3))
    nodes[:, 0] = np.arange(n + 1)
    model = Model(nodes)
    for i, k in enumerate(ks):
        model.add(f"k{i + 1}", "spring", [[i + (0 if wall else 1), i + 1 + (0 if wall else 1)]], SpringProperty((k, 0, 0, 0, 0, 0)))
    for i, m in enumerate(ms):
        model.add(f"m{i + 1}", "mass", [[i + 1]], MassProperty(float(m)))
    model.fix(np.arange(n + 1), [1, 2, 3, 4, 5])
    if wall:
        model.fix(0)
    model.free = not wall
    return model


@pytest.fixture(scope="module")
def string_case():
    return thesis_case("T5.5_string_10dof")


@pytest.fixture(scope="module")
def string_model(string_case):
    return chain(np.array(string_case["inputs"]["k_pa_MN_per_m"]) * 1e6, string_case["inputs"]["m_pa_kg"])


def away_from(freqs, f_res, gap=0.05):
    """Keep frequencies at least ``gap`` (relative) away from every resonance."""
    far = np.all(np.abs(freqs[:, None] - f_res[None]) > gap * f_res[None], axis=1)
    return freqs[far]


def rel_err(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


DAMPINGS = [
    dict(alpha=3.0, beta=2e-5),  # viscous proportional C = alpha M + beta K
    dict(eta=0.02),  # structural D = eta K
    dict(alpha=1.0, beta=1e-5, eta=0.01),
    dict(),  # undamped
]


@pytest.mark.parametrize("damping", DAMPINGS)
def test_modal_with_all_modes_equals_direct(string_model, damping):
    modes = solve_modes(string_model, n_modes=10)
    assert modes.frequencies.size == 10
    f = away_from(np.linspace(1.0, 300.0, 120), modes.frequencies)
    resp, exc = ux(np.array([1, 5, 10])), ux(np.array([3, 7]))
    Hm = frf_modal(modes, f, resp, exc, **damping)
    Hd = frf_direct(string_model, f, resp, exc, **damping)
    assert Hm.shape == (f.size, 3, 2)
    assert rel_err(Hm, Hd) < 1e-6
    # reciprocity: H_ij = H_ji
    H = frf_direct(string_model, f[:5], resp, resp, **damping)
    np.testing.assert_allclose(H, np.transpose(H, (0, 2, 1)), rtol=1e-10)


def test_free_model_rigid_modes_in_superposition():
    """A free chain: the rigid-body mode's 1/(-w^2 + i w alpha) term makes modal and direct agree."""
    rng = np.random.default_rng(0)
    model = chain(rng.uniform(1e4, 3e4, 5), rng.uniform(0.1, 0.3, 6), wall=False)
    modes = solve_modes(model, n_modes=20)
    assert modes.n_rigid == 1 and modes.frequencies.size == 5
    f = away_from(np.linspace(0.5, 150.0, 80), modes.frequencies)
    for damping in (dict(alpha=2.0, beta=1e-5), dict(eta=0.03)):
        Hm = frf_modal(modes, f, ux(np.arange(1, 7)), ux(np.array([1, 4])), **damping)
        Hd = frf_direct(model, f, ux(np.arange(1, 7)), ux(np.array([1, 4])), **damping)
        assert rel_err(Hm, Hd) < 1e-6


def test_a_free_body_accelerance_at_0_hz_is_the_inverse_of_its_mass():
    """At 0 Hz a unit force anywhere on a free chain accelerates it as a rigid body, 1 / sum(m) at every DOF
    (the rigid term was -w^2 / -w^2 = 0 * inf there: NaN, written as NAN into every simulated test's FRFs);
    with mass-proportional damping the limit is 0; the receptance has none."""
    rng = np.random.default_rng(1)
    ms = rng.uniform(0.1, 0.3, 6)
    modes = solve_modes(chain(rng.uniform(1e4, 3e4, 5), ms, wall=False), n_modes=20)
    A = frf_modal(modes, [0.0, 1e-3], ux(np.arange(1, 7)), ux(np.array([1, 4])), zeta=0.01, kind="accelerance")
    np.testing.assert_allclose(A[0], 1.0 / ms.sum(), rtol=1e-9)
    np.testing.assert_allclose(A[1], A[0], rtol=1e-6)
    damped = frf_modal(modes, [0.0], ux(np.arange(1, 7)), ux(np.array([1, 4])), alpha=2.0, kind="accelerance")
    assert np.all(damped == 0)
    assert not np.isfinite(frf_modal(modes, [0.0], ux(np.array([1])), ux(np.array([1])), kind="receptance")).any()


def sdof(k, m):
    model = Model([[0.0, 0.0, 0.0]])
    model.add("k", "spring", [[0]], SpringProperty((k, 0, 0, 0, 0, 0)))
    model.add("m", "mass", [[0]], MassProperty(m))
    model.fix(0, [1, 2, 3, 4, 5])
    return model


def test_single_dof_peaks():
    k, m = 4e4, 0.25
    wn = np.sqrt(k / m)
    fn = wn / (2 * np.pi)
    model = sdof(k, m)
    modes = solve_modes(model, n_modes=1)
    np.testing.assert_allclose(modes.frequencies, [fn], rtol=1e-12)
    zeta, eta = 0.02, 0.05
    # viscous: |H(w_n)| = 1 / (2 zeta k); maximum 1 / (2 zeta k sqrt(1 - zeta^2)) at w_n sqrt(1 - 2 zeta^2)
    f_peak = fn * np.sqrt(1 - 2 * zeta**2)
    Hm = frf_modal(modes, [fn, f_peak], [0], [0], zeta=zeta)[:, 0, 0]
    Hd = frf_direct(model, [fn, f_peak], [0], [0], beta=2 * zeta / wn)[:, 0, 0]  # beta w_n = 2 zeta
    for H in (Hm, Hd):
        np.testing.assert_allclose(abs(H[0]), 1 / (2 * zeta * k), rtol=1e-10)
        np.testing.assert_allclose(abs(H[1]), 1 / (2 * zeta * k * np.sqrt(1 - zeta**2)), rtol=1e-10)
    grid = np.linspace(0.9 * fn, 1.1 * fn, 20001)
    assert abs(frf_modal(modes, grid, [0], [0], zeta=zeta)).max() <= abs(Hm[1]) * (1 + 1e-12)
    # structural: maximum 1 / (eta k) at w_n, response in quadrature with the force
    Hs_m = frf_modal(modes, [fn], [0], [0], eta=eta)[0, 0, 0]
    Hs_d = frf_direct(model, [fn], [0], [0], eta=eta)[0, 0, 0]
    for H in (Hs_m, Hs_d):
        np.testing.assert_allclose(H, -1j / (eta * k), rtol=1e-10)
    assert abs(frf_modal(modes, grid, [0], [0], eta=eta)).max() <= 1 / (eta * k) * (1 + 1e-12)


def test_mobility_and_accelerance(string_model):
    modes = solve_modes(string_model, n_modes=10)
    f = np.array([7.0, 45.0, 120.0])
    w = 2 * np.pi * f
    for fn, kw in ((frf_modal, dict(zeta=0.01)), (frf_direct, dict(eta=0.01))):
        src = modes if fn is frf_modal else string_model
        H = fn(src, f, [ux(2)], [ux(8)], **kw)
        Y = fn(src, f, [ux(2)], [ux(8)], kind="mobility", **kw)
        A = fn(src, f, [ux(2)], [ux(8)], kind="accelerance", **kw)
        np.testing.assert_allclose(Y[:, 0, 0], 1j * w * H[:, 0, 0], rtol=1e-13)
        np.testing.assert_allclose(A[:, 0, 0], -(w**2) * H[:, 0, 0], rtol=1e-13)


@pytest.mark.parametrize("which", ["initial", "experimental"])
def test_thesis_string_receptance_H53(string_case, which):
    """Table 5.5 string: undamped receptance, force at mass 3, response at mass 5, at the updating
    frequencies of Table 5.6, against the independent re-computation (printed to 4 decimals)."""
    sfx = "pa" if which == "initial" else "px"
    model = chain(np.array(string_case["inputs"][f"k_{sfx}_MN_per_m"]) * 1e6, string_case["inputs"][f"m_{sfx}_kg"])
    rec = string_case["ours"]["receptance_H53"]
    ref = np.array(rec[f"log10_abs_H_{which}_m_per_N"])
    f = np.array(rec["f_Hz"])
    Hd = frf_direct(model, f, [ux(5)], [ux(3)])[:, 0, 0]
    Hm = frf_modal(solve_modes(model, n_modes=10), f, [ux(5)], [ux(3)])[:, 0, 0]
    for H in (Hd, Hm):
        np.testing.assert_array_equal(np.round(np.log10(np.abs(H)), 4), ref)


def test_residual_flexibility_restores_static_and_low_frequency_response(string_model):
    K, M = assemble(string_model)
    all_modes = solve_modes(string_model, n_modes=10)
    few = solve_modes(string_model, n_modes=4)
    resp, exc = ux(np.array([2, 5, 9])), ux(np.array([3, 10]))
    R = residual_flexibility(string_model, few, resp, exc, K=K, M=M)
    # exact: R is the static compliance of modes 5..10
    phi_i, phi_j = all_modes.shapes[resp][:, 4:], all_modes.shapes[exc][:, 4:]
    np.testing.assert_allclose(R, (phi_i / all_modes.omega2[4:]) @ phi_j.T, rtol=1e-8)
    static = frf_direct(string_model, [0.0], resp, exc)[0]
    np.testing.assert_allclose(frf_modal(few, [0.0], resp, exc, residual=R)[0], static, rtol=1e-10)
    # below the band of the missing modes, what the residual misses is their dynamic part, of
    # relative size (w / w_5)^2 <= 0.09 here
    f = away_from(np.linspace(2.0, 0.3 * all_modes.frequencies[4], 30), few.frequencies)
    Hd = frf_direct(string_model, f, resp, exc, eta=0.01)
    err_plain = np.abs(frf_modal(few, f, resp, exc, eta=0.01) - Hd)
    err_res = np.abs(frf_modal(few, f, resp, exc, eta=0.01, residual=R) - Hd)
    assert np.all(err_res <= 0.1 * err_plain)


def test_residual_flexibility_free_model():
    rng = np.random.default_rng(1)
    model = chain(rng.uniform(1e4, 3e4, 7), rng.uniform(0.1, 0.3, 8), wall=False)
    all_modes = solve_modes(model, n_modes=20)
    few = solve_modes(model, n_modes=3)
    resp, exc = ux(np.array([1, 4, 8])), ux(np.array([2, 8]))
    R = residual_flexibility(model, few, resp, exc)
    expected = (all_modes.shapes[resp][:, 3:] / all_modes.omega2[3:]) @ all_modes.shapes[exc][:, 3:].T
    np.testing.assert_allclose(R, expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())


def test_bad_frf_arguments(string_model):
    modes = solve_modes(string_model, n_modes=3)
    with pytest.raises(ValueError, match="kind"):
        frf_modal(modes, [10.0], [ux(1)], [ux(1)], kind="velocity")
    with pytest.raises(ValueError, match="response_dofs"):
        frf_direct(string_model, [10.0], [10**6], [ux(1)])
    with pytest.raises(ValueError, match="zeta"):
        frf_modal(modes, [10.0], [ux(1)], [ux(1)], zeta=[0.01, 0.02])
    with pytest.raises(ValueError, match="freqs"):
        frf_modal(modes, [-1.0], [ux(1)], [ux(1)])
