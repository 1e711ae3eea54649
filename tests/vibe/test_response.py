"""Base-excited random response by modal superposition, checked against Miles' equation on a
simply supported plate, against direct integration of the directly solved FRF, and Steinberg's
position factors and the curvature operator against the plate's sine shape."""

import numpy as np
import pytest
import scipy.sparse as sp
from vibe_plates import A, B, navier, solve, write_free_plate, write_plate
from scipy.integrate import quad_vec, trapezoid

from pcbdyn.fe.curvature import curvature_matrix
from pcbdyn.fe.modal import reduced_system
from pcbdyn.fe.probe import model_probe
from pcbdyn.vibration import Psd, assess, judged_parts, parse_damping
from pcbdyn.vibration.base_excitation import base_excitation, influence_vector
from pcbdyn.vibration.spectra import G, frequency_grid


def flat(lo, hi, g2_hz):
    return Psd("flat", "", np.array([lo, hi]), np.full(2, g2_hz * G**2))


def test_centre_of_a_simply_supported_plate_follows_miles(steinberg_plate):
    """Miles: an oscillator on white noise W has z_rms^2 = W / (8 zeta w^3) (relative displacement,
    exact for white noise; Miles' G_rms = sqrt(pi/2 f Q W) divided by w^2). At the centre of the
    plate the (1,1) mode enters with Gamma phi = 16 / pi^2 (sin-sin shape, mass-normalised)."""
    board, bm, modes, K, M = steinberg_plate
    assert modes.frequencies[0] == pytest.approx(navier(1, 1), rel=0.01)
    psd = flat(20.0, 2000.0, 0.04)
    a = assess(board, bm, modes, K, M, psd, parse_damping("zeta=0.03"))
    w1 = 2 * np.pi * modes.frequencies[0]
    miles = 16 / np.pi**2 * np.sqrt(psd.w[0] / (8 * 0.03 * w1**3))
    centre = next(p for p in a.parts if p.ref == "U1")
    assert centre.z_rms_m == pytest.approx(miles, rel=0.02)
    assert abs(centre.z_rms_m / miles - 1) < 0.005  # measured: -0.1 % (band 20-2000 Hz, other modes)
    assert centre.rate_hz == pytest.approx(modes.frequencies[0], rel=0.02)  # one mode: nu0 = f1
    assert a.z_peak_m == pytest.approx(centre.z_rms_m, rel=0.01)  # the centre moves most
    j = a.parts.index(centre)  # the response PSDs are the parts' own, in the table's order
    assert trapezoid(a.part_z_psd[:, j], a.grid) == pytest.approx(centre.z_rms_m**2, rel=1e-9)


def test_position_factors_are_steinbergs_on_a_simply_supported_board(steinberg_plate):
    """Steinberg's r: 1 at the centre, 0.707 at the half/quarter point, 0.5 at the quarter/quarter
    point: sin(pi x/a) sin(pi y/b), here read from the response to a band below the second mode."""
    board, bm, modes, K, M = steinberg_plate
    a = assess(board, bm, modes, K, M, flat(100.0, 500.0, 0.04), parse_damping("steinberg"))
    r = {p.ref: p.position_factor for p in a.parts}
    assert r["U1"] == pytest.approx(1.0, abs=0.01)
    assert r["U2"] == pytest.approx(0.707, rel=0.02)
    assert r["U3"] == pytest.approx(0.5, rel=0.02)
    for p in a.parts:  # the allowable for the board's peak is Steinberg's Z(r) = Z(1) / r
        assert p.z_allow_board_m == pytest.approx(p.z_allow_m / p.position_factor, rel=1e-9)


def test_curvatures_of_the_first_mode_match_the_sine_shape(steinberg_plate):
    """w = sin(pi x/a) sin(pi y/b) gives kappa_xx = -w_xx = (pi/a)^2 w and kappa_yy = (pi/b)^2 w.
    Read at a point, the derivative of the bilinear rotations is first-order accurate: within
    (h/2) |d kappa/dx| / kappa of the exact one, up to 5 % at these points (h = 5 mm)."""
    _, bm, modes, _, _ = steinberg_plate
    pts = np.array([[0.05, 0.04], [0.08, 0.05], [0.11, 0.07], [0.03, 0.02]])
    phi = modes.shapes[:, 0]
    kappa = (curvature_matrix(bm.model, pts) @ phi).reshape(-1, 3)
    w = model_probe(bm.model, np.column_stack([pts, np.zeros(len(pts))])).P @ phi
    np.testing.assert_allclose(kappa[:, 0] / w, (np.pi / A) ** 2, rtol=0.05)
    np.testing.assert_allclose(kappa[:, 1] / w, (np.pi / B) ** 2, rtol=0.05)
    # the twist w_xy = (pi^2/ab) cos cos: zero at the centre, there it is the largest curvature's 1 %
    assert abs(kappa[1, 2]) < 0.01 * abs(kappa[1, 1])


def test_two_modes_match_direct_integration_of_the_directly_solved_frf(tmp_path):
    """A band over the first two modes, Rayleigh damping (so that modes and the direct solve of the
    thesis' dynamic stiffness, eq. 3.28, K(1 + i w beta) + (i w alpha - w^2) M, describe one damped
    structure), a sloped PSD: the RMS
    relative displacement and absolute acceleration at a point where both modes move, from modal
    superposition on pcbdyn's grid, against adaptive quadrature of |H(f)|^2 W(f) with H from the
    direct solve at each frequency."""
    board, bm, modes, K, M = solve(write_plate(tmp_path, 20.0), 6000.0)
    f = modes.frequencies
    w1, w2 = 2 * np.pi * f[:2]
    z1, z2 = 0.02, 0.03
    beta = 2 * (z2 * w2 - z1 * w1) / (w2**2 - w1**2)
    alpha = 2 * z1 * w1 - beta * w1**2
    zeta = alpha / (4 * np.pi * f) + beta * np.pi * f
    psd = Psd("sloped", "", np.array([150.0, 400.0, 900.0]), np.array([0.01, 0.04, 0.04]) * G**2)
    assert f[1] < 900.0 < f[2]
    at = np.array([[0.045, 0.03, 0.0]])
    be = base_excitation(bm.model, modes, K, M, zeta, "z")
    grid = frequency_grid(psd.f[0], psd.f[-1], be.frequencies, be.zeta)
    Bz = be.columns(model_probe(bm.model, at).P)
    Ba = be.columns(model_probe(bm.model, at).P, "acceleration")
    z_modal = np.sqrt(be.variance(Bz, be.covariance(psd, grid)))[0]
    a_modal = np.sqrt(be.variance(Ba, be.covariance(psd, grid, "acceleration")))[0]

    red, Kr, Mr = reduced_system(bm.model, K, M)
    T = sp.csr_matrix(red.T)
    load = -(T.T @ (M @ influence_vector(M.shape[0], "z")))
    read = model_probe(bm.model, at).P @ T

    def integrand(fr):
        w = 2 * np.pi * fr
        u = sp.linalg.spsolve(((1 + 1j * w * beta) * Kr + (1j * w * alpha - w**2) * Mr).tocsc(), load)
        z = (read @ u)[0]
        acc = 1.0 - w**2 * z  # absolute acceleration per unit base acceleration (r = 1 in z)
        return np.array([abs(z) ** 2, abs(acc) ** 2]) * psd.at([fr])[0]

    ms, _ = quad_vec(integrand, psd.f[0], psd.f[-1], points=list(f[:2]), epsrel=1e-6, limit=400)
    z_direct, a_direct = np.sqrt(ms)
    assert z_modal == pytest.approx(z_direct, rel=0.01)
    assert a_modal == pytest.approx(a_direct, rel=0.01)
    assert abs(z_modal / z_direct - 1) < 1e-3 and abs(a_modal / a_direct - 1) < 1e-3  # measured: < 0.05 %


def test_free_board_is_refused(tmp_path):
    board, bm, modes, K, M = solve(write_free_plate(tmp_path), 2000.0)
    from pcbdyn.vibration import VibrationError

    with pytest.raises(VibrationError, match=r"free.toml: the model is free .*declare how the board is held in "
                                             r"\[\[fixtures\]\]"):
        assess(board, bm, modes, K, M, flat(20, 2000, 0.04), parse_damping(None), parts=judged_parts(board))
