"""PBC (thesis section 6.4.1): frequencies alone cannot fix the common scale of masses and
stiffnesses; a second configuration with a known added mass acts as a calibration."""

import warnings

import numpy as np
import pytest

from pcbdyn.updating import (
    Configuration,
    RankDeficiencyWarning,
    condition_numbers,
    frequencies_hz,
    frequency_equations,
    solve_ls,
    pencil_modes,
    stack,
    svd_reduce,
    unit_row_weights,
    update,
    weight_rows,
)

N = 4
P_TRUE = np.array([1.0, 2.0, 1.0e4, 2.5e4])  # [m(1,2), m(3,4), k(1,2), k(3,4)]
P_INIT = np.array([1.15, 1.8, 1.2e4, 2.2e4])


def _chain(added=None):
    """4-DOF fixed-free chain with grouped parameters; ``added`` = (DOF, kg) of a known mass."""
    E = [np.diag(v) for v in ([1, 1, 0, 0], [0, 0, 1, 1])]
    springs = []
    for i in range(N):
        d = np.zeros((N, N))
        d[i, i] = 1
        if i:
            d[i - 1, i - 1] = 1
            d[i - 1, i] = d[i, i - 1] = -1
        springs.append(d)
    G = [springs[0] + springs[1], springs[2] + springs[3]]
    dM0 = np.zeros((N, N))
    if added is not None:
        dM0[added[0], added[0]] = added[1]
    Z = np.zeros((N, N))

    def model(p):
        M = p[0] * E[0] + p[1] * E[1] + dM0
        K = p[2] * G[0] + p[3] * G[1]
        return K, M, [Z, Z] + G, E + [Z, Z]

    return model


def _config(added):
    model = _chain(added)
    K, M, _, _ = model(P_TRUE)
    return Configuration(model, f_x=frequencies_hz(pencil_modes(K, M)[0]), method="freq", name=str(added))


def _blocks(configs, p):
    out = []
    for c in configs:
        K, M, dKs, dMs = c.model(p)
        lam, Phi = pencil_modes(K, M)
        blk = frequency_equations(lam, Phi, c.f_x, dKs, dMs, p)
        out.append(weight_rows(blk.A, blk.b, unit_row_weights(blk.A)))
    return out


def test_one_configuration_is_scale_ambiguous():
    cfg = _config(None)
    with pytest.warns(RankDeficiencyWarning):
        res = update(cfg, P_INIT, tol_freq_pct=1e-8, tol_param_pct=1e-8, max_iter=20)
    assert res.history[0]["condition_per_configuration"][0] == np.inf
    assert "rank deficient" in res.history[0]["message"]
    assert res.history[-1]["max_freq_error_pct"] < 1e-6  # the frequencies are matched...
    assert not np.allclose(res.p, P_TRUE, rtol=1e-3)  # ...by a scaled, wrong parameter set
    ratio = res.p / P_TRUE
    assert np.allclose(ratio, ratio[0], rtol=1e-6)  # exactly the common-scale family


@pytest.mark.parametrize("reduce", [False, True])
def test_mass_perturbed_second_configuration_makes_it_identifiable(reduce):
    configs = [_config(None), _config((0, 0.5))]
    cond = condition_numbers(_blocks(configs, P_INIT))
    assert cond["per_configuration"][0] == np.inf
    assert np.isfinite(cond["stacked"]) and cond["stacked"] < 1e3
    with warnings.catch_warnings():
        warnings.simplefilter("error", RankDeficiencyWarning)
        res = update(configs, P_INIT, stack_reduce=reduce, tol_freq_pct=1e-9, tol_param_pct=1e-9, max_iter=20)
    assert res.converged
    assert np.allclose(res.p, P_TRUE, rtol=1e-9)
    assert all(np.isfinite(h["condition_stacked"]) for h in res.history)


def test_svd_reduced_stacking_keeps_the_least_squares_solution():
    rng = np.random.default_rng(1)
    blocks = [(rng.normal(size=(30, 4)), rng.normal(size=30)) for _ in range(3)]
    full = solve_ls(*stack(blocks)).x
    red = solve_ls(*stack(blocks, reduce=True)).x
    assert np.allclose(full, red, atol=1e-12)
    assert svd_reduce(*blocks[0]).A.shape == (4, 4)


def test_log_scale_update_gives_the_same_solution():
    """Stiffnesses on a log scale (p <- p exp(x)) reach the same exact parameters."""
    configs = [_config(None), _config((0, 0.5))]
    res = update(configs, P_INIT, log_scale=[2, 3], tol_freq_pct=1e-9, tol_param_pct=1e-9, max_iter=20)
    assert res.converged and np.allclose(res.p, P_TRUE, rtol=1e-9)
