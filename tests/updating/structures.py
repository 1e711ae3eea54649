"""Plain-matrix test structures for the updating tests: the thesis' 10-DOF string (Table 5.5) and
18-element cantilever (Table 5.3), built in numpy so they are exact and fast."""


import numpy as np

from reference import thesis_case as _thesis_case


def load_case(name):
    return _thesis_case(name)


def chain_model(n):
    """Fixed-free chain wall-k1-m1-k2-...-kn-mn; parameters p = [m1..mn, k1..kn]."""
    dMs, dKs = [], []
    for i in range(n):
        d = np.zeros((n, n))
        d[i, i] = 1.0
        dMs.append(d)
    for i in range(n):  # k_{i+1} joins DOF i-1 (or the wall) and DOF i
        d = np.zeros((n, n))
        d[i, i] = 1.0
        if i > 0:
            d[i - 1, i - 1] = 1.0
            d[i - 1, i] = d[i, i - 1] = -1.0
        dKs.append(d)
    zeros = [np.zeros((n, n))] * n

    def model(p):
        p = np.asarray(p, float)
        M = sum(pj * d for pj, d in zip(p[:n], dMs))
        K = sum(pj * d for pj, d in zip(p[n:], dKs))
        return K, M, zeros + dKs, dMs + zeros

    return model


def beam_model(L, b, h, rho, n_el):
    """Clamped planar Euler-Bernoulli cantilever, Hermite elements (w, theta per node), consistent
    mass; parameters p = Young's modulus of each element."""
    Le = L / n_el
    I, A = b * h**3 / 12, b * h
    k = np.array([[12, 6 * Le, -12, 6 * Le], [6 * Le, 4 * Le**2, -6 * Le, 2 * Le**2],
                  [-12, -6 * Le, 12, -6 * Le], [6 * Le, 2 * Le**2, -6 * Le, 4 * Le**2]]) * I / Le**3
    m = np.array([[156, 22 * Le, 54, -13 * Le], [22 * Le, 4 * Le**2, 13 * Le, -3 * Le**2],
                  [54, 13 * Le, 156, -22 * Le], [-13 * Le, -3 * Le**2, -22 * Le, 4 * Le**2]]) * rho * A * Le / 420
    n = 2 * n_el  # node 0 clamped: DOFs of nodes 1..n_el
    dKs, M = [], np.zeros((n, n))
    for e in range(n_el):
        full = np.zeros((n + 2, n + 2))
        idx = np.arange(2 * e, 2 * e + 4)
        full[np.ix_(idx, idx)] = k
        dKs.append(full[2:, 2:])
        fm = np.zeros((n + 2, n + 2))
        fm[np.ix_(idx, idx)] = m
        M += fm[2:, 2:]
    zeros = [np.zeros((n, n))] * n_el

    def model(p):
        return sum(pj * d for pj, d in zip(p, dKs)), M, dKs, zeros

    return model


def frf(model, p, omegas, j, C=None):
    """Receptances of every DOF for a unit force at DOF j (optionally with viscous damping C)."""
    K, M, _, _ = model(p)
    cols = []
    for w in omegas:
        Z = K - w**2 * M + (1j * w * C if C is not None else 0)
        e = np.zeros(K.shape[0])
        e[j] = 1.0
        cols.append(np.linalg.solve(Z, e))
    return np.column_stack(cols)


def updating_omegas():
    """The ten updating frequencies of thesis Table 5.6 [rad/s]."""
    return 2 * np.pi * np.array(load_case("T5.5_string_10dof")["thesis"]["updating_frequencies_Table5.6_Hz"], float)
