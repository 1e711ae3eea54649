"""Thesis cantilever (Table 5.3, section 5.4.1): 18 Euler-Bernoulli elements, E5-E8 at 20 GPa
instead of 26.68 GPa, its first 8 frequencies as data."""

import warnings

import numpy as np
import pytest

from pcbdyn.updating import (
    Configuration,
    RankDeficiencyWarning,
    frequencies_hz,
    frequency_equations,
    solve_ls,
    pencil_modes,
    success_ratio,
    svd_qr,
    tls_qrf,
    unit_row_weights,
    update,
    weight_rows,
)

ERRORS = [4, 5, 6, 7]  # E5..E8


def _fx(model, p):
    K, M, _, _ = model(p)
    return frequencies_hz(pencil_modes(K, M, 8)[0])


def test_test_model_is_the_tables_beam(cantilever):
    """The numpy beam reproduces the independent re-computation of Table 5.3 (plain consistent mass)."""
    model, p_a, p_x, case = cantilever
    ref = case["plain_consistent_mass"]
    assert np.allclose(_fx(model, p_a), ref["fa"], rtol=1e-4)
    assert np.allclose(_fx(model, p_x), ref["fx"], rtol=1e-4)


@pytest.mark.parametrize("solver,method", [("ls", "freq"), ("tls", "freq"), ("bounded", "freq"),
                                           ("bayes", "freq"), ("ls", "freq-rel")])
def test_four_moduli_recovered_from_8_frequencies(cantilever, solver, method):
    model, p_a, p_x, _ = cantilever
    cfg = Configuration(model, f_x=_fx(model, p_x), method=method)
    held = np.setdiff1d(np.arange(18), ERRORS)
    bounds = (0.5 * p_a, 1.5 * p_a)
    res = update(cfg, p_a, solver=solver, fixed=held, bounds=bounds, tol_freq_pct=1e-4,
                 tol_param_pct=1e-6, tol_sigma_pct=1e-9, max_iter=40)
    assert res.converged, res.reason
    assert np.allclose(res.p[ERRORS], p_x[ERRORS], rtol=5e-3)
    assert np.array_equal(res.p[held], p_a[held])
    assert res.history[-1]["max_freq_error_pct"] < 1e-4
    assert res.history[0]["max_freq_error_pct"] > 2.5  # Table 5.3: 2.6-4.5 % initially


def test_bounded_solver_stops_at_the_bound(cantilever):
    """A lower bound above the true value is respected and reported as active."""
    model, p_a, p_x, _ = cantilever
    cfg = Configuration(model, f_x=_fx(model, p_x), method="freq")
    held = np.setdiff1d(np.arange(18), ERRORS)
    lower = 0.9 * p_a  # true E5-E8 are 0.75 p_a
    res = update(cfg, p_a, solver="bounded", fixed=held, bounds=(lower, 1.5 * p_a), max_iter=10)
    assert np.all(res.p[ERRORS] >= lower[ERRORS] * (1 - 1e-9))
    assert np.allclose(res.p[ERRORS], lower[ERRORS], rtol=1e-6)
    assert res.solution.info["active_bounds"].size == 4


def _equations(cantilever):
    model, p_a, p_x, _ = cantilever
    K, M, dKs, dMs = model(p_a)
    lam, Phi = pencil_modes(K, M, 8)
    blk = frequency_equations(lam, Phi, _fx(model, p_x), dKs, dMs, p_a)
    return weight_rows(blk.A, blk.b, unit_row_weights(blk.A))


def test_eighteen_moduli_rank_is_reported(cantilever):
    A, b = _equations(cantilever)
    with pytest.warns(RankDeficiencyWarning, match="8 < 18 parameters"):
        sol = solve_ls(A, b)
    assert sol.rank == 8 and sol.rank_deficient
    assert sol.null_space.shape == (18, 10)
    assert np.all(np.isfinite(sol.condition_curve[:8])) and np.all(np.isinf(sol.condition_curve[8:]))


def test_tls_qrf_localises_e5_to_e8_and_svd_qr_fails(cantilever):
    """Thesis Fig. 5.13/5.14: TLS/QR-F 100 % noise-free; SVD/QR expels every error parameter."""
    A, b = _equations(cantilever)
    loc = tls_qrf(A, b)
    assert loc.rank == 8
    assert set(loc.order[:4]) == set(ERRORS)  # the four errors are the first picks
    assert loc.descending_ratio[0] > 40  # thesis Fig. 5.13c: about 60 % for the first pick
    assert success_ratio(loc.selected, ERRORS) == 100.0
    assert np.all(loc.x[ERRORS] < -0.2)  # about the -25 % of Table 5.2
    sq = svd_qr(A, b)
    assert not set(sq.order) & set(ERRORS)
    assert success_ratio(sq.selected, ERRORS) == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RankDeficiencyWarning)
        mn = solve_ls(A, b)  # minimum-norm LS spreads the error over many moduli (Fig. 5.13f)
    from pcbdyn.updating import threshold_selection

    assert success_ratio(threshold_selection(mn.x), ERRORS) < 100.0
