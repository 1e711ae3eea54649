"""The small numerical examples printed in the thesis: TLS vs LS (section 4.5), the QR basic
solution (eq. 5.35), SVD/QR (eq. 5.36) and the cos^2 criterion (section 5.2.3)."""

import numpy as np
import pytest

from pcbdyn.updating import choose_rank, qr_basic_solution, solve_ls, solve_tls, svd_qr
from pcbdyn.updating.subset import descending_ratios, qrf_forward

A535 = np.array([[0.0504, 4.4522, 1.9878, 5.4599], [-0.6758, 4.7639, 3.0169, 4.3587],
                 [4.0380, -1.9781, 0.0005, 5.9816], [1.6469, 0.3732, -5.9917, 3.6867],
                 [-2.5746, 4.2454, 2.0054, -0.2060], [-0.9051, 4.4779, -1.0116, 3.4383]])
B535 = np.array([10.9450, 8.3795, 13.9822, 8.1968, -1.6994, 6.4241])


def test_tls_and_ls_line_fit():
    a = np.array([[0.98], [3.01], [5.10]])
    b = np.array([1.20, 2.85, 5.30])
    assert solve_ls(a, b).x[0] == pytest.approx(1.0209, abs=1e-4)
    assert solve_tls(a, b, t_b=1.0).x[0] == pytest.approx(1.0223, abs=1e-4)


def test_tls_exact_on_consistent_data():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(30, 5))
    x = rng.normal(size=5)
    assert np.allclose(solve_tls(A, A @ x).x, x, atol=1e-10)


def test_qr_basic_solution():
    sub = qr_basic_solution(A535, B535)
    assert sub.rank == 3
    assert np.allclose(sub.x, [0.0, -0.2884, -0.0064, 2.2422], atol=1e-4)


def test_svd_qr_on_perturbed_matrix():
    A = np.array([[0.0433, 4.4481, 1.9877, 5.4633], [-0.6487, 4.7795, 3.0172, 4.3456],
                  [4.0244, -1.9859, 0.0003, 5.9882], [1.6511, 0.3756, -5.9916, 3.6847],
                  [-2.5985, 4.2316, 2.0051, -0.1944], [-0.9106, 4.4748, -1.0117, 3.4409]])
    sub = svd_qr(A, B535, rank=3)
    assert list(sub.order) == [2, 3, 1]  # thesis: columns 3, 4, 2
    assert np.allclose(sub.x, [0.0, -0.2884, -0.0064, 2.2421], atol=2e-4)


def test_cos2_picks_the_column_parallel_to_b():
    W = np.array([[2.0, 1, 3, 2], [-7, 2, 5, 9], [3, 4, 1, 4]])
    w = np.array([0.95, 2.01, 4.05])
    assert qrf_forward(W, w)[0] == 1  # cos^2 = [0.0000, 0.9998, 0.3846, 0.6075]


def test_descending_ratio_example():
    """Section 5.2.3 example: R upper triangular, b_r = [4, -3, 2, -1]."""
    R = np.array([[3.0, 2, 4, 2], [0, 2, 5, 1], [0, 0, 1, 7], [0, 0, 0, 0.5]])
    Rr, dRr = descending_ratios(R, np.array([4.0, -3, 2, -1]))
    nb = np.sqrt(30.0)
    assert np.allclose(Rr, 100 * np.array([nb, np.sqrt(14), np.sqrt(5), 1, 0]) / nb)
    assert dRr.sum() == pytest.approx(100.0)


def test_rank_from_condition_jump():
    s = np.array([10.0, 5.0, 2.0, 1e-5, 1e-6])
    assert choose_rank(s) == 3
    assert choose_rank(np.array([3.0, 2.0, 1.0])) == 3
    assert choose_rank(np.array([1.0, 0.5, 1e-12])) == 2
    steps = np.array([10.0, 9.0, 8.0, 7.0, 2.0])  # one 3.5x step in an otherwise flat curve
    assert choose_rank(steps) == 5
    assert choose_rank(steps, rel_jump=2.5) == 4


def test_chi_square_row_weights_use_the_standard_deviations():
    """Eq. 4.28: rows weighted by 1/sigma_i give the maximum-likelihood estimate; with very
    unequal noise it beats plain LS (averaged over repeated draws)."""
    from pcbdyn.updating import std_row_weights, weight_rows

    rng = np.random.default_rng(3)
    A = rng.normal(size=(40, 3))
    x = np.array([1.0, -2.0, 0.5])
    sigma = np.where(np.arange(40) < 20, 1e-3, 1.0)
    err_w, err_ls = [], []
    for _ in range(50):
        b = A @ x + sigma * rng.normal(size=40)
        err_ls.append(np.linalg.norm(solve_ls(A, b).x - x))
        err_w.append(np.linalg.norm(solve_ls(*weight_rows(A, b, std_row_weights(sigma))).x - x))
    assert np.mean(err_w) < 0.1 * np.mean(err_ls)
    with pytest.raises(ValueError, match="sigma"):
        std_row_weights([1.0, 0.0])
