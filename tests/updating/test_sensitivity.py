"""Eigenvalue and eigenvector derivatives (thesis eqs. 3.6, 3.8-3.14) against central finite
differences of full re-solves."""

import numpy as np

from pcbdyn.fe import BeamProperty, MassProperty, Model
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import reduce_matrix, reduced_system
from pcbdyn.fe.properties import SpringProperty
from pcbdyn.updating import (
    eigenvalue_derivatives,
    eigenvector_derivative_nelson,
    eigenvector_derivatives_modal,
    frequencies_hz,
    frequency_derivatives,
    pencil_modes,
)


def _fd(resolve, p, j, n_modes, h=1e-5):
    dp = h * p[j]
    up, dn = p.copy(), p.copy()
    up[j] += dp
    dn[j] -= dp
    return (resolve(up)[:n_modes] - resolve(dn)[:n_modes]) / (2 * dp)


def _check(model, p, n_modes):
    K, M, dKs, dMs = model(p)
    lam, Phi = pencil_modes(K, M, n_modes)
    analytic = eigenvalue_derivatives(lam, Phi, dKs, dMs)

    def resolve(q):
        K, M, _, _ = model(q)
        return pencil_modes(K, M, n_modes)[0]

    for j in range(p.size):
        fd = _fd(resolve, p, j, n_modes)
        scale = np.max(np.abs(fd)) + 1e-300
        assert np.max(np.abs(analytic[:, j] - fd)) / scale < 1e-4, j
        assert np.allclose(analytic[:, j], fd, rtol=1e-4, atol=1e-6 * scale), j
    return lam, Phi, dKs, dMs


def test_chain_mass_and_spring_parameters(string10):
    model, p_a, _ = string10
    lam, Phi, dKs, dMs = _check(model, p_a, 10)
    # frequency form of eq. 3.6 is the chain rule of f = sqrt(lambda) / 2 pi
    df = frequency_derivatives(lam, Phi, dKs, dMs)
    dl = eigenvalue_derivatives(lam, Phi, dKs, dMs)
    assert np.allclose(df, dl / (8 * np.pi**2 * frequencies_hz(lam))[:, None])


def test_beam_moduli(cantilever):
    model, p_a, p_x, _ = cantilever
    _check(model, p_x, 8)


def test_fe_beam_spring_mass_parameters():
    """pcbdyn.fe model: beam modulus and density, a grounded spring and a point mass as parameters."""
    n_el, L = 6, 0.3
    x = np.linspace(0, L, n_el + 1)
    nodes = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    sec = dict(nu=0.3, A=2e-5, Iy=1e-11, Iz=4e-11, J=2e-11, orientation=(0.0, 1.0, 0.0))
    conn = np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)])

    def build(p):
        E, rho, k, m = p
        mdl = Model(nodes)
        mdl.add("root", "beam2", conn[:3], BeamProperty(E=E, rho=rho, **sec))
        mdl.add("tip", "beam2", conn[3:], BeamProperty(E=70e9, rho=2700.0, **sec))
        mdl.add("spring", "spring", [[n_el]], SpringProperty(k=(0.0, k, k, 0.0, 0.0, 0.0)))
        mdl.add("mass", "mass", [[n_el // 2]], MassProperty(m=m))
        mdl.fix(0)
        return mdl

    def model(p):
        mdl = build(p)
        K, M = assemble(mdl)
        red, Kr, Mr = reduced_system(mdl, K, M)
        E, rho, k, m = p
        Kroot, Mroot = assemble(mdl, sets=["root"])
        dK = [Kroot / E, 0 * K, assemble(mdl, sets=["spring"])[0] / k, 0 * K]
        dM = [0 * M, Mroot / rho, 0 * M, assemble(mdl, sets=["mass"])[1] / m]
        return Kr, Mr, [reduce_matrix(red, d) for d in dK], [reduce_matrix(red, d) for d in dM]

    _check(model, np.array([70e9, 2700.0, 500.0, 0.02]), 6)


def test_eigenvector_derivatives(string10):
    """Nelson's method equals finite differences; the modal sum over all modes (eqs. 3.8-3.14)
    equals Nelson's result when every mode is kept."""
    model, p_a, _ = string10
    K, M, dKs, dMs = model(p_a)
    lam, Phi = pencil_modes(K, M)
    i, j = 3, 14
    nelson = eigenvector_derivative_nelson(K, M, lam[i], Phi[:, i], dKs[j], dMs[j])
    modal = eigenvector_derivatives_modal(lam, Phi, i, dKs, dMs)[:, j]
    h = 1e-6 * p_a[j]

    def shape(dp):
        q = p_a.copy()
        q[j] += dp
        Kq, Mq, _, _ = model(q)
        v = pencil_modes(Kq, Mq)[1][:, i]
        return v * np.sign(v @ (M @ Phi[:, i]))

    fd = (shape(h) - shape(-h)) / (2 * h)
    assert np.allclose(nelson, fd, rtol=1e-4, atol=1e-4 * np.abs(fd).max())
    assert np.allclose(modal, nelson, rtol=1e-8, atol=1e-10 * np.abs(nelson).max())
    # mass-normalisation is kept to first order: 2 phi^T M dphi + phi^T dM phi = 0 (eq. 3.13)
    assert abs(2 * Phi[:, i] @ M @ nelson + Phi[:, i] @ dMs[j] @ Phi[:, i]) < 1e-10 * np.abs(nelson).max()


def test_fe_shell_thickness_and_density():
    """Clamped plate strip of quad4 shells: thickness of one element group (enters as t and t^3)
    and density, derivatives by the perturbation method (eq. 4.50)."""
    from pcbdyn.fe import ShellProperty
    from pcbdyn.updating import perturbation_derivatives

    nx, ny, a, b = 6, 3, 0.12, 0.06
    xs, ys = np.linspace(0, a, nx + 1), np.linspace(0, b, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    nodes = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    nid = np.arange(X.size).reshape(nx + 1, ny + 1)
    quads = np.array([[nid[i, j], nid[i + 1, j], nid[i + 1, j + 1], nid[i, j + 1]] for i in range(nx) for j in range(ny)])
    part = np.array([i >= 3 for i in range(nx) for j in range(ny)])

    def build_model(p):
        t, rho = p
        mdl = Model(nodes)
        mdl.add("board", "quad4", quads[~part], ShellProperty(E=2.5e10, nu=0.3, rho=1900.0, t=1.6e-3))
        mdl.add("part", "quad4", quads[part], ShellProperty(E=2.5e10, nu=0.3, rho=rho, t=t))
        mdl.fix(nid[0])
        return mdl

    def model(p):
        mdl = build_model(p)
        K, M = assemble(mdl)
        red, Kr, Mr = reduced_system(mdl, K, M)
        derivs = [perturbation_derivatives(lambda q: assemble(build_model(q), sets=["part"]), p, j) for j in range(2)]
        return Kr, Mr, [reduce_matrix(red, d[0]) for d in derivs], [reduce_matrix(red, d[1]) for d in derivs]

    _check(model, np.array([2.4e-3, 2600.0]), 5)


def test_sparse_free_chain_modes():
    """Large (ARPACK) path with a singular K: free-free unit chain, lambda_k = 2 - 2 cos(pi k / n)."""
    import scipy.sparse as sp

    n = 2000
    L = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n)).tolil()
    L[0, 0] = L[n - 1, n - 1] = 1.0
    lam, Phi = pencil_modes(L.tocsc(), sp.eye(n, format="csc"), 4)
    exact = 2 - 2 * np.cos(np.pi * np.arange(4) / n)
    assert abs(lam[0]) < 1e-12 and np.allclose(lam[1:], exact[1:], rtol=1e-8)
    assert np.allclose(Phi.T @ Phi, np.eye(4), atol=1e-8)
