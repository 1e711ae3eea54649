"""MAC/COMAC and mode pairing on analytical simply-supported plate modes sin(m pi x/a) sin(n pi y/b)."""

import numpy as np
import pytest

from pcbdyn.correlation import automac, comac, mac, pair_modes, subspace_mac
from pcbdyn.testdata import noisy_frequencies, noisy_shapes

A, B = 0.162, 0.178  # board-sized plate [m]


def plate_mode(m, n, x, y, a=A, b=B):
    return np.sin(m * np.pi * x / a) * np.sin(n * np.pi * y / b)


def plate_freq(m, n, a=A, b=B, c=50.0):
    """Proportional to the SS plate frequency: (m/a)^2 + (n/b)^2 (c absorbs pi/2 sqrt(D/rho h))."""
    return c * ((m / a) ** 2 + (n / b) ** 2)


def grid(nx, ny, a=A, b=B):
    x, y = np.meshgrid(np.linspace(0, a, nx + 2)[1:-1], np.linspace(0, b, ny + 2)[1:-1], indexing="ij")
    return x.ravel(), y.ravel()


def mode_set(x, y, mn, a=A, b=B):
    shapes = np.column_stack([plate_mode(m, n, x, y, a, b) for m, n in mn])
    return shapes, np.array([plate_freq(m, n, a, b) for m, n in mn])


def test_mac_of_a_mode_with_itself_is_one_whatever_its_scale_and_sign():
    x, y = grid(9, 9)
    phi = plate_mode(2, 3, x, y)
    assert mac(phi, phi)[0, 0] == pytest.approx(1.0, abs=1e-14)
    assert mac(phi, -3.7 * phi)[0, 0] == pytest.approx(1.0, abs=1e-14)
    # a complex, phase-rotated copy is still the same mode
    assert mac(phi * np.exp(0.7j), phi)[0, 0] == pytest.approx(1.0, abs=1e-14)


def test_orthogonal_plate_modes_on_a_dense_random_sampling_have_mac_below_one_percent():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, A, 2500), rng.uniform(0, B, 2500)
    M = automac(mode_set(x, y, [(1, 1), (1, 2), (2, 1), (2, 2), (3, 1)])[0])
    off = M[~np.eye(5, dtype=bool)]
    assert off.max() < 0.01
    assert np.allclose(np.diag(M), 1.0)


def test_comac_is_one_for_identical_sets_and_flags_the_corrupted_dof():
    """Eq. 2.4 takes |products|: a sign error is invisible to it, a mode-dependent gain is not."""
    x, y = grid(8, 8)
    phi, _ = mode_set(x, y, [(1, 1), (2, 1), (1, 2), (2, 2)])
    assert np.allclose(comac(phi, 5.0 * phi), 1.0)
    flipped = phi.copy()
    flipped[17] *= -1
    assert np.allclose(comac(flipped, phi), 1.0)
    bad = phi.copy()
    bad[17] *= [1.0, 0.1, 3.0, 0.2]  # one sensor whose gain drifted from mode to mode
    c = comac(bad, phi)
    assert np.argmin(c) == 17
    assert c[17] < 0.9 and np.delete(c, 17).min() > 0.95


def test_pairing_recovers_a_shuffled_noisy_set_and_reports_unpaired_modes():
    x, y = grid(10, 10)
    mn = [(1, 1), (2, 1), (1, 2), (2, 2), (3, 1), (1, 3), (3, 2), (2, 3), (4, 1), (1, 4)]
    phi_a, f_a = mode_set(x, y, mn)
    rng = np.random.default_rng(7)
    perm = rng.permutation(len(mn))[:8]  # 8 of the 10 model modes were measured, in random order
    phi_x = noisy_shapes(phi_a[:, perm], 5.0, rng) + 0.05 * rng.uniform(-1, 1, (x.size, perm.size))
    f_x = noisy_frequencies(f_a[perm] * 1.03, 1.0, rng)
    phi_x = np.column_stack([phi_x, rng.standard_normal(x.size)])  # a spurious test "mode"
    f_x = np.append(f_x, 1.5 * f_a.max())
    p = pair_modes(phi_x, phi_a, f_x, f_a, min_mac=0.6)
    assert [q.test for q in p.pairs] == list(range(8))
    assert [q.model for q in p.pairs] == perm.tolist()
    assert min(q.mac for q in p.pairs) > 0.9
    assert p.unpaired_test == [8]
    assert sorted(p.unpaired_model) == sorted(set(range(10)) - set(perm.tolist()))
    d = p.to_dict()
    assert d["pairs"][0]["test_mode"] == 1 and d["pairs"][0]["model_mode"] == perm[0] + 1
    assert d["pairs"][0]["df_pct"] == pytest.approx(100 * (f_a[perm[0]] - f_x[0]) / f_x[0])


def test_nearly_repeated_model_modes_are_paired_through_their_best_combination():
    a = b = 0.15  # square plate: (1,2) and (2,1) are a repeated pair
    x, y = grid(9, 9, a, b)
    phi_a, f_a = mode_set(x, y, [(1, 1), (1, 2), (2, 1), (2, 2)], a, b)
    f_a[2] *= 1.001  # a slight asymmetry splits the pair by 0.1 %
    th = np.deg2rad(30.0)
    rot = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    test_pair = phi_a[:, 1:3] @ rot  # what the test sees: two orthogonal mixtures of the pair
    phi_x = np.column_stack([phi_a[:, 0], test_pair, phi_a[:, 3]])
    f_x = f_a * 1.01
    single = mac(test_pair, phi_a[:, 1:3])
    assert single.max() == pytest.approx(np.cos(th) ** 2, abs=0.02)  # no single model mode matches
    p = pair_modes(phi_x, phi_a, f_x, f_a, min_mac=0.9)
    assert [q.model for q in p.pairs] == [0, 1, 2, 3]
    for q in p.pairs[1:3]:
        assert q.cluster == (1, 2)
        assert q.mac_combined > 1 - 1e-10
        assert q.mac < 0.9
    combined = p.model_shapes(phi_a)
    assert np.allclose(np.diag(mac(phi_x, combined)), 1.0, atol=1e-10)
    val, u = subspace_mac(test_pair[:, 0], phi_a[:, 1:3])
    assert val == pytest.approx(1.0, abs=1e-12)
    assert np.allclose(np.abs(u), np.abs(rot[:, 0]), atol=1e-10)


def test_a_pair_below_the_minimum_mac_cannot_displace_a_good_one():
    """Test mode A matches model a (0.95) and b (0.81); B matches only a, poorly (0.15). Maximising
    the plain MAC sum would take A-b + B-a (0.96) over A-a + B-b (0.95) and then drop B-a."""
    c2 = 0.85
    a = np.array([1.0, 0.0, 0.0])
    b = np.array([np.sqrt(c2), np.sqrt(1 - c2), 0.0])
    A_ = np.array([np.sqrt(0.95), 0.0, np.sqrt(0.05)])
    B_ = np.array([np.sqrt(1 - c2), -np.sqrt(c2), 0.0])  # orthogonal to b
    phi_x, phi_a = np.column_stack([A_, B_]), np.column_stack([a, b])
    M = mac(phi_x, phi_a)
    assert M[0, 1] + M[1, 0] > M[0, 0] + M[1, 1]
    p = pair_modes(phi_x, phi_a, [100.0, 200.0], [100.0, 200.0], min_mac=0.5)
    assert [(q.test, q.model) for q in p.pairs] == [(0, 0)]
    assert p.unpaired_test == [1] and p.unpaired_model == [1]


def test_model_modes_that_alias_on_a_sparse_grid_pair_by_frequency_and_are_reported():
    """On a 3 x 3 grid near the sixth points of a square SS plate, the (1,2) and (5,2) modes read nearly alike
    (sin(5 pi / 6) = sin(pi / 6), sin(5 pi / 2) = sin(pi / 2): AutoMAC 1 at the sixth points, 0.9 here). A test
    of the (1,2) mode with channel errors that make it resemble (5,2) more: MAC alone pairs it at +470 %;
    paired by frequency within what the grid cannot tell apart it goes to (1,2), and the pairing names the two
    modes."""
    a = b = 0.15
    g = np.array([0.185, 0.5, 0.815]) * a
    x, y = (v.ravel() for v in np.meshgrid(g, g, indexing="ij"))
    mn = [(1, 1), (1, 2), (2, 1), (5, 2)]
    phi_a, f_a = mode_set(x, y, mn, a, b)
    f_a[2] *= 1.02  # (1,2) and (2,1): a pair split by 2 %, not a cluster
    auto = automac(phi_a)[1, 3]
    assert 0.8 < auto < 0.95
    unit = phi_a / np.linalg.norm(phi_a, axis=0)
    x12 = unit[:, 1] + 1.5 * unit[:, 3]  # errors towards what the grid cannot tell from (1,2)
    phi_x = np.column_stack([phi_a[:, 0], x12, phi_a[:, 2]])
    f_x = f_a[:3] * 1.02
    M = mac(phi_x, phi_a)
    assert M[1, 3] > M[1, 1] > 0.8
    p = pair_modes(phi_x, phi_a, f_x, f_a)
    assert [(q.test, q.model) for q in p.pairs] == [(0, 0), (1, 1), (2, 2)]
    assert p.pairs[1].aliased == (3,) and all(q.used for q in p.pairs)
    assert [(j, k) for j, k, _ in p.aliases] == [(1, 3)]
    assert f"model modes 2 and 4 look alike at the test points (AutoMAC {auto:.2f})" in p.warnings()[0]


def test_a_pair_beyond_the_frequency_limit_is_reported_and_not_used_for_updating():
    """A test mode whose only look-alike model mode is 50 % higher: the pair is kept in the report, marked not
    used, and the updating's pairing callable leaves that test mode out (-1)."""
    from pcbdyn.problems import ShapePairing

    x, y = grid(6, 6)
    phi_a, f_a = mode_set(x, y, [(1, 1), (2, 1), (1, 2)])
    phi_x = phi_a[:, [0, 2]]
    f_x = np.array([f_a[0] * 1.01, f_a[2] / 1.5])
    p = pair_modes(phi_x, phi_a, f_x, f_a, limit=0.3)
    assert [(q.test, q.model, q.used) for q in p.pairs] == [(0, 0, True), (1, 2, False)]
    assert p.pairs[1].df_pct == pytest.approx(50.0)
    assert p.warnings() == ["test mode 2 pairs with model mode 3 at +50.0 %, beyond the 30 % limit: reported, not "
                            "used for updating"]
    assert p.to_dict()["pairs"][1]["used"] is False
    pairing = ShapePairing(0.5)
    assert pairing(f_a, phi_a, f_x, phi_x).tolist() == [0, -1]
    assert pairing.warnings() == p.warnings()


def test_alias_groups_chain_through_shared_neighbours_and_skip_undefined_automac():
    """Clusters join where any of their modes look alike (AutoMAC >= the limit), transitively: the
    first and third of {0}, {1, 2}, {3} alias only through the second; an AutoMAC left undefined (a
    mode with no motion at the points) joins nothing."""
    from pcbdyn.correlation.pairing import aliased

    auto = np.full((5, 5), 0.1)
    np.fill_diagonal(auto, 1.0)
    auto[0, 2] = auto[2, 0] = auto[2, 3] = auto[3, 2] = 0.95
    groups = [[0], [1, 2], [3], [4]]
    assert aliased(groups, auto, 0.9) == [[0, 1, 2], [3]]
    assert aliased(groups, auto, 0.96) == [[0], [1], [2], [3]]
    auto[3, 4] = auto[4, 3] = 0.99
    auto[2, 4] = auto[4, 2] = np.nan
    assert aliased(groups, auto, 0.9) == [[0, 1, 2, 3]]
    assert aliased([[0], [1, 2], [4]], auto, 0.9) == [[0, 1], [2]]
