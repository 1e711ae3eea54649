"""Test design numerics on plain arrays (pcbdyn.updating.design, issue 41): grouped Effective Independence
against brute force, D-optimal choice against exhaustive search, predicted standard deviations."""

from itertools import combinations

import numpy as np
import pytest

from pcbdyn.updating import design


def brute_force_groups(Phi, groups, n_keep):
    """Greedy elimination by brute force: drop the group whose removal leaves the largest det(Phi^T Phi)."""
    keep = sorted(set(groups.tolist()))
    while len(keep) > n_keep:
        def left(g):
            rows = np.isin(groups, [k for k in keep if k != g])
            return np.linalg.slogdet(Phi[rows].T @ Phi[rows])[1]
        keep.remove(max(keep, key=left))
    return keep


@pytest.mark.parametrize("seed", range(4))
def test_triaxial_efi_is_greedy_determinant_elimination(seed):
    rng = np.random.default_rng(seed)
    Phi = rng.normal(size=(3 * 20, 5))
    groups = np.repeat(np.arange(20), 3)
    got = design.effective_independence(Phi, 4, groups)
    assert sorted(got.tolist()) == brute_force_groups(Phi, groups, 4)


def test_efi_refuses_too_few_sensors_and_blind_candidates():
    Phi = np.random.default_rng(0).normal(size=(10, 4))
    with pytest.raises(ValueError, match="cannot tell 4 modes apart"):
        design.effective_independence(Phi, 3)
    Phi[:, 3] = 0.0
    with pytest.raises(ValueError, match="singular"):
        design.effective_independence(Phi, 6)


def test_guard_bounds_the_automac_and_keeps_efi_when_it_already_holds():
    rng = np.random.default_rng(2)
    Phi = rng.normal(size=(40, 4))
    free = design.choose_sensors(Phi, 10, max_automac=1.0)
    assert free.log_det >= free.efi_log_det  # exchanges only raise it
    tight = design.choose_sensors(Phi, 10, max_automac=0.05)
    G = Phi[tight.chosen].T @ Phi[tight.chosen]
    assert tight.automac_max == pytest.approx(float(design.automac_offdiag(G)))
    assert tight.automac_max <= 0.05


@pytest.mark.parametrize("seed", range(5))
def test_d_optimal_pair_matches_exhaustive_search(seed):
    rng = np.random.default_rng(seed)
    A0 = rng.normal(size=(3, 4))  # the base determines only 3 of 4 directions
    cands = [rng.normal(size=(2, 4)) * rng.uniform(0.2, 2.0) for _ in range(15)]
    F0, Fc = A0.T @ A0, np.stack([A.T @ A for A in cands])
    groups = np.arange(15) // 3  # three masses at each of five places: one per place
    got = design.d_optimal(F0, Fc, 2, groups)
    best = max((pair for pair in combinations(range(15), 2) if groups[pair[0]] != groups[pair[1]]),
               key=lambda pair: design.log_det(F0 + Fc[list(pair)].sum(axis=0)))
    assert design.log_det(F0 + Fc[got].sum(axis=0)) == pytest.approx(design.log_det(F0 + Fc[list(best)].sum(axis=0)))
    assert groups[got[0]] != groups[got[1]]


def test_predicted_std_is_the_covariance_diagonal_and_infinite_when_undetermined():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(8, 3))
    F = A.T @ A
    np.testing.assert_allclose(design.predicted_std(F), np.sqrt(np.diag(np.linalg.inv(F))))
    A[:, 2] = A[:, 1]  # two parameters the rows cannot tell apart; the first is still determined
    std = design.predicted_std(A.T @ A)
    assert np.isfinite(std[0]) and np.isinf(std[1:]).all()
