"""Expansion, smoothing and orthogonality on small exact models built with pcbdyn.fe (dense matrices)."""

import numpy as np
import pytest
import scipy.linalg as sla

from pcbdyn.correlation import cross_orthogonality, mixed_orthogonality, off_diagonal_ratio, static_mass
from pcbdyn.correlation.expansion import (
    kidder_expansion,
    modal_expansion,
    serep_expansion,
    serep_test_based,
    shifted_frequencies,
    smooth_frfs,
    smooth_shapes,
)
from pcbdyn.fe import BeamProperty, MassProperty, Model, SpringProperty, dof_index
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import reduced_system
from pcbdyn.fe.reduction import master_index

RHO, AREA, LENGTH, TIP = 2700.0, 0.02 * 0.004, 0.4, 0.05


def cantilever(n_el=16):
    """Aluminium strip 400 x 20 x 4 mm clamped at x = 0, a 50 g tip mass."""
    x = np.linspace(0.0, LENGTH, n_el + 1)
    model = Model(np.column_stack([x, 0 * x, 0 * x]))
    b, h = 0.02, 0.004
    prop = BeamProperty(E=70e9, nu=0.33, rho=RHO, A=AREA, Iy=h * b**3 / 12, Iz=b * h**3 / 12, J=b * h**3 / 3,
                        orientation=(0.0, 0.0, 1.0))
    model.add("beam", "beam2", np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)]), prop)
    model.add("tip", "mass", [[n_el]], MassProperty(TIP))
    model.fix(0)
    return model


@pytest.fixture(scope="module")
def beam():
    model = cantilever()
    red, K, M = reduced_system(model)
    K, M = K.toarray(), M.toarray()
    lam, Phi = sla.eigh(K, M)
    # a vibrometer's view: uz (flapwise bending, across the 4 mm thickness) at 6 of the 16 nodes
    measured_nodes = np.array([3, 6, 8, 11, 13, 16])
    meas = master_index(red, dof_index(measured_nodes, "uz").ravel())
    return model, red, K, M, lam, Phi, meas


def flexural(Phi, meas, n):
    """Indices of the first n modes that move the measured (transverse) DOFs."""
    amp = np.abs(Phi[meas]).max(0) / np.abs(Phi).max(0)
    out = np.flatnonzero(amp > 0.01)[:n]
    assert out.size == n
    return out


@pytest.mark.parametrize("form", ["slave", "all"])
def test_dynamic_expansion_of_an_exact_mode_reproduces_the_full_shape(beam, form):
    _, _, K, M, lam, Phi, meas = beam
    modes = flexural(Phi, meas, 3)
    phi_full = Phi[:, modes]
    expanded = kidder_expansion(K, M, meas, phi_full[meas], np.sqrt(lam[modes]), form=form)
    err = np.abs(expanded - phi_full).max(0) / np.abs(phi_full).max(0)
    assert err.max() < 1e-8


def spring_chain(n=7):
    """Masses on a line joined by axial springs (k_i differ), fixed at one end: a 7-DOF system in ux."""
    model = Model(np.column_stack([np.arange(n + 1.0), np.zeros(n + 1), np.zeros(n + 1)]))
    for i in range(n):
        model.add(f"k{i}", "spring", [[i, i + 1]], SpringProperty((1e4 * (1 + 0.3 * i), 0, 0, 0, 0, 0)))
        model.add(f"m{i}", "mass", [[i + 1]], MassProperty(0.5 + 0.1 * i))
    model.fix(0)
    model.fix(np.arange(1, n + 1), ["uy", "uz", "rx", "ry", "rz"])
    return model


def test_dynamic_expansion_from_the_master_rows_is_exact_when_they_determine_the_slaves():
    """Eq. 2.26 uses only the master rows of Z phi = 0: it needs every slave coupled to the masters."""
    model = spring_chain()
    red, K, M = reduced_system(model)
    K, M = K.toarray(), M.toarray()
    lam, Phi = sla.eigh(K, M)
    assert K.shape == (7, 7)
    meas = master_index(red, dof_index([1, 2, 4, 6, 7], "ux").ravel())  # masses 3 and 5 are slaves
    expanded = kidder_expansion(K, M, meas, Phi[meas], np.sqrt(lam), form="master")
    assert np.abs(expanded - Phi).max() / np.abs(Phi).max() < 1e-8
    # total moving mass (eq. 2.10) is the sum of the lumped masses
    Kf, Mf = assemble(model)
    assert static_mass(Mf, axis=0) == pytest.approx(sum(0.5 + 0.1 * i for i in range(7)), rel=1e-12)


def test_serep_equals_modal_coordinate_expansion_and_smooths_the_measured_rows(beam):
    _, _, K, M, lam, Phi, meas = beam
    modes = flexural(Phi, meas, 4)
    Phi_a = Phi[:, modes]
    rng = np.random.default_rng(2)
    phi_x = Phi_a[meas] @ np.array([1.0, 0.1, -0.05, 0.02]) + 0.02 * rng.standard_normal(meas.size)
    by_serep = serep_expansion(Phi_a, meas, phi_x)
    by_modal = modal_expansion(Phi_a, phi_x, measured=meas)
    assert np.allclose(by_serep, by_modal, rtol=0, atol=1e-12 * np.abs(by_modal).max())
    smoothed = smooth_shapes(Phi_a[meas], phi_x)
    assert np.allclose(by_serep[meas], smoothed, atol=1e-12)
    # the measured part moves onto the model's subspace: the residual is orthogonal to it
    assert np.abs(Phi_a[meas].T @ (phi_x - smoothed)).max() < 1e-12
    # reading the model through an interpolation matrix (here a selection) gives the same expansion
    P = np.zeros((meas.size, Phi.shape[0]))
    P[np.arange(meas.size), meas] = 1.0
    assert np.allclose(modal_expansion(Phi_a, phi_x, read=P), by_modal, atol=1e-12)


def test_test_based_serep_returns_the_model_part_for_paired_scaled_modes(beam):
    _, _, K, M, lam, Phi, meas = beam
    modes = flexural(Phi, meas, 3)
    Phi_a = Phi[:, modes]
    slaves = np.setdiff1d(np.arange(Phi.shape[0]), meas)
    Phi_x = Phi_a[meas] * np.array([2.0, -0.5, 3.0])  # the test scaled each mode its own way
    out = serep_test_based(Phi_a[slaves], Phi_x)
    assert np.allclose(out, Phi_a[slaves], atol=1e-12)


def test_orthogonality_of_expanded_exact_modes_and_total_mass(beam):
    model, _, K, M, lam, Phi, meas = beam
    modes = flexural(Phi, meas, 3)
    expanded = kidder_expansion(K, M, meas, Phi[meas][:, modes], np.sqrt(lam[modes]))
    mixed_m, mixed_k = mixed_orthogonality(expanded, M, K)
    assert off_diagonal_ratio(mixed_m).max() < 1e-8
    assert np.allclose(np.diag(mixed_k), lam[modes], rtol=1e-8)
    cross = cross_orthogonality(Phi[:, modes], expanded, M)
    assert np.allclose(cross, np.eye(3), atol=1e-8)
    Kf, Mf = assemble(model)
    for axis in range(3):
        assert static_mass(Mf, axis) == pytest.approx(RHO * AREA * LENGTH + TIP, rel=1e-12)


def test_frf_smoothing_projects_on_the_shifted_model_frfs_and_drops_unlike_lines():
    f_u = shifted_frequencies([98.0, 101.0, 205.0], f_test=[100.0, 200.0], f_model=[95.0, 210.0])
    assert np.allclose(f_u, [93.0, 96.0, 215.0])
    rng = np.random.default_rng(5)
    n_resp, n_u = 12, 5
    H_ae = rng.standard_normal((n_u, n_resp)) + 1j * rng.standard_normal((n_u, n_resp))
    mix = rng.standard_normal((n_u, n_u)) + 1j * rng.standard_normal((n_u, n_u))
    H_x = mix @ H_ae  # test vectors that lie in the span of the model's
    smoothed, keep = smooth_frfs(H_x, H_ae)
    assert keep.all() and np.allclose(smoothed, H_x, atol=1e-12)
    noise = 0.05 * np.abs(H_x).max() * (rng.standard_normal(H_x.shape) + 1j * rng.standard_normal(H_x.shape))
    smoothed, _ = smooth_frfs(H_x + noise, H_ae)
    assert np.linalg.norm(smoothed - H_x) < 0.7 * np.linalg.norm(noise)
    # a test line whose response vector is orthogonal to the model's is not used (FDAC = 0)
    H_bad = H_x.copy()
    v = rng.standard_normal(n_resp) + 1j * rng.standard_normal(n_resp)
    H_bad[2] = v - H_ae[2] * (H_ae[2].conj() @ v) / (H_ae[2].conj() @ H_ae[2])
    _, keep = smooth_frfs(H_bad, H_ae, min_fdac=0.01)
    assert keep.tolist() == [True, True, False, True, True]
