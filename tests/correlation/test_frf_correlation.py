"""FRAC and FDAC against analytical single- and two-DOF frequency responses."""

import numpy as np
import pytest
from scipy.integrate import quad

from pcbdyn.correlation import fdac, frac


def sdof(w, wn, zeta):
    """Receptance per unit mass of a viscously damped oscillator."""
    return 1.0 / (wn**2 - w**2 + 2j * zeta * wn * w)


def test_frac_is_one_for_identical_frfs():
    w = np.linspace(10, 2000, 3001)
    h = sdof(w, 2 * np.pi * 150, 0.02)[:, None, None]
    assert frac(h, 3.0 * h)[0, 0] == pytest.approx(1.0, abs=1e-13)


def test_frac_drops_as_predicted_for_a_two_percent_frequency_shift():
    wn, zeta, shift = 2 * np.pi * 200.0, 0.01, 1.02
    lo, hi = 0.5 * wn, 1.5 * wn
    w = np.linspace(lo, hi, 40001)
    f = frac(sdof(w, shift * wn, zeta), sdof(w, wn, zeta))
    # independent value: the continuous band integrals of eq. 2.5, by adaptive quadrature
    pts = [wn, shift * wn]
    re = quad(lambda v: (np.conj(sdof(v, wn, zeta)) * sdof(v, shift * wn, zeta)).real, lo, hi, points=pts, limit=400)[0]
    im = quad(lambda v: (np.conj(sdof(v, wn, zeta)) * sdof(v, shift * wn, zeta)).imag, lo, hi, points=pts, limit=400)[0]
    n1 = quad(lambda v: abs(sdof(v, wn, zeta)) ** 2, lo, hi, points=pts, limit=400)[0]
    n2 = quad(lambda v: abs(sdof(v, shift * wn, zeta)) ** 2, lo, hi, points=pts, limit=400)[0]
    expected = (re**2 + im**2) / (n1 * n2)
    assert f == pytest.approx(expected, rel=1e-4)
    # and the physics: one pole each, half-power width sigma = zeta wn, shift d -> 1 / (1 + (d / 2 sigma)^2)
    pole_model = 1.0 / (1.0 + ((shift - 1) * wn / (2 * zeta * wn)) ** 2)
    assert pole_model == pytest.approx(0.5)
    assert f == pytest.approx(pole_model, abs=0.03)


def two_dof(w, stiffness_scale=1.0, eta=0.02):
    M = np.diag([1.0, 1.5])
    K = stiffness_scale * 1e6 * np.array([[2.0, -1.0], [-1.0, 1.0]])
    Z = K[None] * (1 + 1j * eta) - (w**2)[:, None, None] * M[None]
    return np.linalg.inv(Z)  # (n_freq, 2, 2): both responses, both references


def test_fdac_ridge_sits_on_the_diagonal_for_identical_frfs_and_moves_by_the_frequency_shift():
    w = np.linspace(200.0, 2000.0, 901)
    Hx = two_dof(w)
    same = fdac(Hx, Hx)
    assert same.shape == (2, w.size, w.size)
    assert np.allclose(np.diagonal(same, axis1=1, axis2=2), 1.0, atol=1e-12)
    # a test 2 % higher in frequency: K' = 1.02^2 K gives H'(1.02 w) = H(w) / 1.0404 exactly
    Hs = two_dof(1.02 * w, stiffness_scale=1.02**2)
    ridge = fdac(Hx, Hs)
    assert np.allclose(np.diagonal(ridge, axis1=1, axis2=2), 1.0, atol=1e-12)
    Ha = two_dof(w, stiffness_scale=1.02**2)  # the same shifted model on the test's own lines
    shifted = fdac(Hx, Ha)
    assert np.diagonal(shifted, axis1=1, axis2=2).min() < 1 - 1e-3  # equal lines no longer agree
    best = w[np.argmax(shifted, axis=2)]  # per test line, the model line that agrees best
    inner = (w > 300) & (w < 1900)
    assert np.allclose(best[:, inner], 1.02 * w[inner], atol=2 * (w[1] - w[0]))
