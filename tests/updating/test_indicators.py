"""Location-oriented indicators (thesis 5.2.1): FBM residual forces (eq. 5.2), EMM (5.3-5.13) and
weighted EMM (5.14-5.22), on the 10-DOF string and the simulated free PCB."""

import numpy as np
import pytest

from pcbdyn.updating import pencil_modes
from pcbdyn.updating.indicators import (
    emm_error_matrices,
    emm_indicators,
    fbm_indicator,
    fbm_residuals,
    node_sum,
    weighted_emm,
    weighted_emm_indicator,
)
from pcbdyn.problems.cases import SimulatedFreePCB

from structures import chain_model


def _string(error_index, factor):
    model = chain_model(10)
    p_a = np.concatenate([np.ones(10), np.full(10, 1e4)])
    p_x = p_a.copy()
    p_x[error_index] *= factor
    Ka, Ma, _, _ = model(p_a)
    Kx, Mx, _, _ = model(p_x)
    return Ka, Ma, Kx, Mx


def test_fbm_residuals_vanish_away_from_the_error():
    """k5 joins masses 4 and 5 (DOFs 3, 4): the residual forces of the exact test modes are
    -dK phi_x, zero at every other DOF, and zero everywhere for the model's own modes."""
    Ka, Ma, Kx, Mx = _string(10 + 4, 1.3)
    lam, phi = pencil_modes(Kx, Mx)
    e = fbm_residuals(Ka, Ma, np.sqrt(lam), phi)
    scale = np.abs(Ka).max() * np.abs(phi).max()
    assert np.all(np.abs(np.delete(e, [3, 4], axis=0)) < 1e-10 * scale)
    assert np.allclose(e, (Ka - Kx) @ phi, atol=1e-10 * scale)  # the mass is right: e = -dK phi_x
    assert np.argmax(fbm_indicator(Ka, Ma, np.sqrt(lam), phi)) in (3, 4)
    lam_a, phi_a = pencil_modes(Ka, Ma)
    assert np.abs(fbm_residuals(Ka, Ma, np.sqrt(lam_a), phi_a)).max() < 1e-9 * scale


def test_emm_with_complete_modes():
    """With all modes the truncated inverses of eqs. 5.7 and 5.9 are exact: a stiffness-only error
    gives dM = 0 and dK = Ka (Ka^-1 - Kx^-1) Ka (eq. 5.4), whose indicator peaks at k5's DOFs."""
    Ka, Ma, Kx, Mx = _string(10 + 4, 1.05)
    la, pa = pencil_modes(Ka, Ma)
    lx, px = pencil_modes(Kx, Mx)
    dK, dM = emm_error_matrices(Ka, Ma, np.sqrt(la), pa, np.sqrt(lx), px)
    assert np.abs(dM).max() < 1e-10 * np.abs(Ma).max()
    assert np.allclose(dK, Ka @ (np.linalg.inv(Ka) - np.linalg.inv(Kx)) @ Ka, atol=1e-8 * np.abs(Ka).max())
    e_m, e_k = emm_indicators(Ka, Ma, dK, dM)
    assert np.argmax(e_k) in (3, 4)
    # a mass error: e_m now peaks at that mass
    Ka, Ma, Kx, Mx = _string(6, 1.05)
    lx, px = pencil_modes(Kx, Mx)
    dK, dM = emm_error_matrices(Ka, Ma, np.sqrt(la), pa, np.sqrt(lx), px)
    assert np.argmax(emm_indicators(Ka, Ma, dK, dM)[0]) == 6


def test_weighted_emm_identity():
    """With the mass right and all modes, B = Phi_x Phi_x^T = M^-1, so E of eq. 5.18 equals
    M^-1 dK + dK M^-1 exactly (eqs. 5.14-5.17)."""
    Ka, Ma, Kx, Mx = _string(10 + 2, 1.2)
    lx, px = pencil_modes(Kx, Mx)
    E = weighted_emm(Ka, Ma, np.sqrt(lx), px)
    Mi, dK = np.linalg.inv(Ma), Kx - Ka
    assert np.allclose(E, Mi @ dK + dK @ Mi, atol=1e-9 * np.abs(E).max())
    assert np.argmax(weighted_emm_indicator(E)) in (1, 2)


@pytest.fixture(scope="module")
def one_thick_part():
    """Simulated free PCB whose only error is element 23 (3.0 -> 3.4 mm)."""
    return SimulatedFreePCB(errors_mm={23: 3.4}, n_modes=20)


def test_maps_of_one_thicker_part_peak_on_it(one_thick_part, tmp_path):
    """FBM from the 7 measured modes on the 56 measured points, and weighted EMM from 20 modes,
    both peak at a node of element 23 (thesis Figs. 5.1, 5.4)."""
    c = one_thick_part
    cfg = c.configs[0]
    corners = set(c.conn[22])
    fbm = fbm_indicator(c.K, cfg["M"], cfg["omega_x"][:7], cfg["phi_x"][:, :7])
    assert int(np.argmax(fbm)) in corners
    wemm = weighted_emm_indicator(weighted_emm(c.K, cfg["M"], cfg["omega_x"], cfg["phi_x"]))
    assert int(np.argmax(wemm)) in corners
    from pcbdyn.report.localisation_plots import save_map

    png = save_map(tmp_path / "fbm.png", c.nodes, c.conn, fbm, "FBM indicator")
    assert png.stat().st_size > 1000


def test_node_sum_groups_dofs():
    v = np.array([1.0, -2.0, 3.0, -4.0])
    assert np.allclose(node_sum(v, [0, 0, 1, 1]), [3.0, 7.0])
    with pytest.raises(ValueError, match="dof_node"):
        node_sum(v, [0, 1])
