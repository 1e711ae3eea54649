"""Guyan, dynamic (Kidder) and SEREP reduction/expansion (thesis ch. 2.2) on a clamped 3-D beam
frame, against full-model static and modal solutions."""

import numpy as np
import pytest
import scipy.linalg as sla

from pcbdyn.fe.modal import reduced_system, solve_modes
from pcbdyn.fe.model import ModelError
from pcbdyn.fe.reduction import dynamic_expansion, dynamic_reduction, guyan, master_index, serep

from frames import three_member_frame


def frame():
    """A non-planar frame of three members, clamped at both ends (6 DOF per node, 16 nodes)."""
    model = three_member_frame([[0, 0, 0], [0.3, 0, 0], [0.3, 0.2, 0], [0.3, 0.2, 0.15]], 5)
    model.fix([0, model.n_nodes - 1])
    return model


@pytest.fixture(scope="module")
def system():
    model = frame()
    red, Kr, Mr = reduced_system(model)
    # "measured" DOFs: the three translations of every other interior node
    nodes = np.arange(2, model.n_nodes - 1, 2)
    masters = master_index(red, (6 * nodes[:, None] + np.arange(3)).ravel())
    return model, red, Kr, Mr, masters


def test_guyan_is_exact_for_loads_at_the_masters(system):
    _, _, Kr, Mr, masters = system
    T, KG, MG = guyan(Kr, Mr, masters)
    rng = np.random.default_rng(0)
    f = np.zeros((Kr.shape[0], 3))
    f[masters] = rng.standard_normal((masters.size, 3))
    x_full = np.linalg.solve(Kr.toarray(), f)
    x_guyan = T @ np.linalg.solve(KG, f[masters])
    np.testing.assert_allclose(x_guyan, x_full, rtol=0, atol=1e-10 * np.abs(x_full).max())
    np.testing.assert_array_equal(T[masters], np.eye(masters.size))
    # Rayleigh-Ritz: Guyan frequencies lie above the exact ones, and close for the lowest modes
    lam_g = sla.eigh(KG, MG, eigvals_only=True)[:4]
    lam = sla.eigh(Kr.toarray(), Mr.toarray(), eigvals_only=True)[:4]
    assert np.all(lam_g >= lam * (1 - 1e-12))
    np.testing.assert_allclose(lam_g[0], lam[0], rtol=1e-2)


def test_dynamic_expansion_of_exact_modes(system):
    model, red, Kr, Mr, masters = system
    modes = solve_modes(model, n_modes=6)
    phi = modes.shapes[red.independent]  # reduced (constrained) shapes
    w = 2 * np.pi * modes.frequencies
    expanded = dynamic_expansion(Kr, Mr, masters, phi[masters], w)
    np.testing.assert_allclose(expanded, phi, rtol=0, atol=1e-8 * np.abs(phi).max())
    one = dynamic_expansion(Kr, Mr, masters, phi[masters, 2], w[2])
    np.testing.assert_allclose(one, phi[:, 2], rtol=0, atol=1e-8 * np.abs(phi).max())
    # Kidder reduction at a natural frequency: the reduced dynamic stiffness annihilates the mode
    T, Zd = dynamic_reduction(Kr, Mr, masters, w[1])
    scale = np.abs(Zd).max() * np.abs(phi[masters, 1]).max()
    assert np.abs(Zd @ phi[masters, 1]).max() < 1e-8 * scale
    np.testing.assert_allclose(T @ phi[masters, 1], phi[:, 1], rtol=0, atol=1e-8 * np.abs(phi).max())
    # ... and at omega = 0 it is Guyan's condensed stiffness
    _, Z0 = dynamic_reduction(Kr, Mr, masters, 0.0)
    _, KG, _ = guyan(Kr, Mr, masters)
    np.testing.assert_allclose(Z0, KG, rtol=1e-10, atol=1e-12 * np.abs(KG).max())


@pytest.mark.parametrize("n_masters", ["square", "more"])
def test_serep_keeps_the_modes_exactly(system, n_masters):
    model, red, Kr, Mr, masters = system
    modes = solve_modes(model, n_modes=6)
    phi = modes.shapes[red.independent]
    if n_masters == "square":  # six masters picked by pivoted QR, so that Phi_m is well conditioned
        m = masters[sla.qr(phi[masters].T, pivoting=True)[2][:6]]
    else:
        m = masters
    T = serep(phi, m)
    Ks, Ms = T.T @ (Kr @ T), T.T @ (Mr @ T)
    if n_masters == "square":
        lam = sla.eigh(Ks, Ms, eigvals_only=True)
    else:  # more masters than modes: Ks, Ms have rank 6; their pencil on the range of Phi_m^+T
        lam = np.sort(np.linalg.eigvals(np.linalg.pinv(Ms, hermitian=True) @ Ks).real)[-6:]
    np.testing.assert_allclose(lam, modes.omega2, rtol=1e-9)
    # expansion of any combination of the modes seen at the masters gives it back everywhere
    q = np.random.default_rng(2).standard_normal((6, 3))
    np.testing.assert_allclose(T @ (phi[m] @ q), phi @ q, rtol=0, atol=1e-9 * np.abs(phi @ q).max())
    np.testing.assert_allclose(T, phi @ np.linalg.pinv(phi[m]), rtol=1e-12, atol=1e-14)


def test_reduction_errors(system):
    model, red, Kr, Mr, masters = system
    with pytest.raises(ModelError, match="not independent"):
        master_index(red, [0, 1])  # node 0 is clamped
    with pytest.raises(ValueError, match="distinct"):
        guyan(Kr, Mr, [masters[0], masters[0]])
    modes = solve_modes(model, n_modes=6)
    phi = modes.shapes[red.independent]
    with pytest.raises(ModelError, match="not independent at the 2 masters"):
        serep(phi, masters[:2])
