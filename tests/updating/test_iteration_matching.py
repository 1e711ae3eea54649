"""Iteration driver behaviour (re-pairing, divergence, bounds of use) and model matching with
measured-DOF subsets."""

import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn.updating import Configuration, RankDeficiencyWarning, pencil_modes, update
from pcbdyn.updating import matching

from structures import frf, updating_omegas


def _modes(model, p):
    K, M, _, _ = model(p)
    lam, Phi = pencil_modes(K, M)
    return np.sqrt(lam) / (2 * np.pi), Phi


def test_shuffled_measured_modes_are_re_paired_by_mac(string10):
    model, p_a, p_x = string10
    f_x, Phi = _modes(model, p_x)
    order = np.array([1, 0, 3, 2, 5, 4, 7, 6, 9, 8])
    calls = []

    def pairing(f_a, phi_a, f_meas, phi_meas):
        from pcbdyn.updating.iteration import mac_pairing

        calls.append(1)
        return mac_pairing(f_a, phi_a, f_meas, phi_meas)

    cfg = Configuration(model, f_x=f_x[order], phi_x=Phi[:, order], method="qms")
    res = update(cfg, p_a, fixed=[1], pairing=pairing, tol_freq_pct=1e-8, tol_param_pct=1e-8)
    assert np.allclose(res.p, p_x, rtol=1e-8)
    assert np.array_equal(res.history[-1]["pairs"][0], order)
    assert len(calls) == len(res.history)


def test_wrong_derivatives_stall_at_the_start(string10):
    """Derivatives of the wrong sign point every step away from the data: the trust region rejects each
    trial, shrinking it down to a fraction of a percent, and the fit stops stalled at the start (the
    objective never rises, so nothing diverges)."""
    model, p_a, p_x = string10
    f_x, _ = _modes(model, p_x)

    def wrong(p):
        K, M, dKs, dMs = model(p)
        return K, M, [-d for d in dKs], [-d for d in dMs]

    cfg = Configuration(wrong, f_x=f_x, method="freq")
    held = np.arange(10)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RankDeficiencyWarning)
        res = update(cfg, p_a, fixed=held, solver="bayes", use_line_search=False, max_iter=20)
    assert res.stalled and not res.converged
    assert "stalled" in res.reason
    assert res.best_iteration == 0 and len(res.history) == 1
    assert np.array_equal(res.p, p_a)
    right = update(Configuration(model, f_x=f_x, method="freq"), p_a, fixed=held, solver="bayes",
                   use_line_search=False, max_iter=20)
    assert right.history[-1]["sigma"] < 0.1 * res.history[0]["sigma"]  # the same fit with the right signs moves


def _selection(n, dofs):
    P = sp.lil_matrix((len(dofs), n))
    for r, d in enumerate(dofs):
        P[r, d] = 1.0
    return P.tocsr()


def test_dynamic_expansion_is_exact_for_true_modes(string10):
    """At its own frequency, the true model expands a measured mode exactly, for a selection P
    (pcbdyn.fe.reduction) and for an interpolating P (constrained form)."""
    model, _, p_x = string10
    K, M, _, _ = model(p_x)
    f, Phi = _modes(model, p_x)
    P_sel = _selection(10, [0, 2, 4, 6, 9])
    P_int = sp.csr_matrix(np.vstack([0.5 * (np.eye(10)[1] + np.eye(10)[2]), np.eye(10)[[4, 7, 9]],
                                     0.3 * np.eye(10)[5] + 0.7 * np.eye(10)[6]]))
    for P in (P_sel, P_int):
        modes = [0, 3, 4]
        exp = matching.expand(K, M, P, P @ Phi[:, modes], 2 * np.pi * f[modes])
        assert np.allclose(exp, Phi[:, modes], atol=1e-10 * np.abs(Phi).max())
    assert matching.selected_dofs(P_int) is None
    assert np.array_equal(matching.selected_dofs(P_sel), [0, 2, 4, 6, 9])
    # Guyan: the selection and the constrained form give the same transformation
    T1 = matching.transformation(K, M, P_sel)
    T2 = matching.transformation(K, M, sp.csr_matrix(P_sel.toarray() * 1.0 + 0.0), None)
    assert np.allclose(T1, T2)
    assert np.allclose(P_sel @ T1, np.eye(5))


ERRORS = [0, 3, 6, 12, 14, 18]  # m1, m4, m7, k3, k5, k9 (Table 5.5)


def test_shape_equations_with_measured_subset_and_expansion(string10):
    """Four modes measured at six of the ten masses, expanded with the current model at every
    iteration (eq. 2.25). The expansion follows the model, so the iteration is a fixed-point one
    (the expanded DOFs carry no residual) rather than Newton's; it still closes most of the
    33 % parameter errors. With every DOF "measured" through P it is exactly the direct case."""
    model, p_a, p_x = string10
    f_x, Phi = _modes(model, p_x)
    held = np.setdiff1d(np.arange(20), ERRORS)
    P = _selection(10, [0, 2, 3, 5, 7, 9])
    cfg = Configuration(model, f_x=f_x[:4], phi_x=P @ Phi[:, :4], P=P, method="qms", matching="expand")
    res = update(cfg, p_a, fixed=held, tol_freq_pct=1e-7, tol_param_pct=1e-7, max_iter=30)
    assert np.max(np.abs(res.p / p_x - 1)) < 0.01 < np.max(np.abs(p_a / p_x - 1))
    assert res.history[-1]["sigma"] < 0.1 * res.history[0]["sigma"]

    P_all = _selection(10, np.arange(10))
    for method in ("fbm", "qms"):
        direct = Configuration(model, f_x=f_x, phi_x=Phi, method=method)
        r2 = update(direct, p_a, fixed=[1], tol_freq_pct=1e-9, tol_param_pct=1e-9)
        for how in ("expand", "reduce"):
            via_p = Configuration(model, f_x=f_x, phi_x=Phi, P=P_all, method=method, matching=how)
            r1 = update(via_p, p_a, fixed=[1], tol_freq_pct=1e-9, tol_param_pct=1e-9)
            assert np.allclose(r1.p, r2.p, rtol=1e-10) and np.allclose(r1.p, p_x, rtol=1e-8)


def test_frf_direct_with_measured_subset(string10):
    """Direct receptance equations (eq. 3.40) need measurements only at the measured DOFs."""
    model, p_a, p_x = string10
    om = updating_omegas()
    P = _selection(10, [1, 2, 4, 6, 8, 9])
    H = P @ frf(model, p_x, om, 2)
    cfg = Configuration(model, frf_omegas=om, H_x=H, excitation=2, P=P, method="frf-direct")
    held = np.setdiff1d(np.arange(20), ERRORS)
    res = update(cfg, p_a, fixed=held, tol_param_pct=1e-7, max_iter=30)
    assert res.converged
    assert np.allclose(res.p, p_x, rtol=1e-6)


def test_bad_input_names_the_field(string10):
    model, p_a, _ = string10
    with pytest.raises(ValueError, match="f_x"):
        Configuration(model, method="freq")
    with pytest.raises(ValueError, match="method"):
        Configuration(model, f_x=[1.0], method="modal")
    with pytest.raises(ValueError, match="bounds"):
        update(Configuration(model, f_x=_modes(model, p_a)[0]), p_a, solver="bounded")


def test_unpaired_measured_mode_is_dropped(string10):
    """A pairing that rejects a measured mode (-1) leaves it out; the others still update exactly."""
    from pcbdyn.updating import mac_pairing

    model, p_a, p_x = string10
    f_x, Phi = _modes(model, p_x)

    def reject_third(f_a, phi_a, f_m, phi_m):
        pairs = mac_pairing(f_a, phi_a, f_m, phi_m)
        pairs[2] = -1
        return pairs

    cfg = Configuration(model, f_x=f_x, phi_x=Phi, method="qms")
    res = update(cfg, p_a, fixed=[1], pairing=reject_third, tol_freq_pct=1e-9, tol_param_pct=1e-9)
    assert np.allclose(res.p, p_x, rtol=1e-8)
    assert res.history[0]["mac"][0].size == 9
