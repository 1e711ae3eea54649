"""Mode pairing by MAC (never by order): an optimal one-to-one assignment with a minimum MAC and the
frequency difference as tie-breaker. Closely spaced or repeated model modes are paired through the
best combination within their subspace (thesis eq. 3.15-3.18).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

from .mac import mac


def subspace_mac(phi_x, Phi_a):
    """Best MAC of ``phi_x`` with any combination Phi_a u of the columns of ``Phi_a`` (thesis eq. 3.18).

    The maximum of the MAC over u is reached at the least-squares fit u = Phi_a^+ phi_x: the squared
    cosine between phi_x and the subspace. Returns (mac, u) with ||u|| = 1, so that for
    mass-orthonormal modes the combination is mass-normalised too (eq. 3.16-3.17).
    """
    x = np.asarray(phi_x).ravel()
    A = np.asarray(Phi_a).reshape(x.size, -1)
    u = np.linalg.lstsq(A, x, rcond=None)[0]
    nu = np.linalg.norm(u)
    if nu == 0:
        return 0.0, np.zeros(A.shape[1])
    u = u / nu
    return float(mac(x, A @ u)[0, 0]), u


def clusters(f_a, rel_tol: float) -> list:
    """Groups of model mode indices whose frequencies chain within ``rel_tol`` of each other."""
    f = np.asarray(f_a, dtype=float)
    order = np.argsort(f)
    groups, cur = [], [int(order[0])] if f.size else []
    for a, b in zip(order[:-1], order[1:]):
        if abs(f[b] - f[a]) <= rel_tol * max(abs(f[a]), abs(f[b])):
            cur.append(int(b))
        else:
            groups.append(cur)
            cur = [int(b)]
    if cur:
        groups.append(cur)
    return groups


@dataclass
class Pair:
    """One test mode paired with one model mode (or a combination of a cluster of close model modes)."""

    test: int
    model: int
    f_test: float
    f_model: float
    mac: float
    mac_combined: float
    cluster: tuple = ()
    coefficients: np.ndarray = field(default_factory=lambda: np.ones(1))

    @property
    def df_pct(self) -> float:
        """(f_model - f_test) / f_test in percent."""
        return 100.0 * (self.f_model - self.f_test) / self.f_test


@dataclass
class Pairing:
    """Pairs, the MAC matrix (n_test, n_model) and the test and model modes left unpaired."""

    pairs: list
    mac: np.ndarray
    unpaired_test: list
    unpaired_model: list

    @property
    def test_index(self) -> np.ndarray:
        return np.array([p.test for p in self.pairs], dtype=int)

    @property
    def model_index(self) -> np.ndarray:
        return np.array([p.model for p in self.pairs], dtype=int)

    def model_shapes(self, shapes) -> np.ndarray:
        """Model shapes (any rows: full vectors or values at test DOFs), one column per pair, with the
        cluster combinations applied (columns of ``shapes`` are the model modes)."""
        S = np.asarray(shapes)
        return np.column_stack([S[:, list(p.cluster)] @ p.coefficients for p in self.pairs]) if self.pairs else S[:, :0]

    def to_dict(self) -> dict:
        """JSON-ready summary with 1-based mode numbers."""
        return {
            "pairs": [
                {"test_mode": p.test + 1, "model_mode": p.model + 1, "f_test_hz": p.f_test, "f_model_hz": p.f_model,
                 "df_pct": p.df_pct, "mac": p.mac_combined, "mac_single": p.mac,
                 "combined_with": [c + 1 for c in p.cluster if c != p.model]}
                for p in self.pairs
            ],
            "unpaired_test_modes": [i + 1 for i in self.unpaired_test],
            "unpaired_model_modes": [j + 1 for j in self.unpaired_model],
        }


def pair_modes(phi_x, phi_a, f_x, f_a, min_mac: float = 0.5, close: float = 0.005,
               freq_weight: float = 1e-3) -> Pairing:
    """Pair test modes (columns of ``phi_x``) with model modes (``phi_a``, read at the same DOFs).

    The assignment (scipy's linear_sum_assignment) maximises the sum of MACs minus ``freq_weight``
    times the relative frequency differences, so frequency only decides between equal MACs. Model
    modes within ``close`` (relative) of each other form a cluster; a test mode is scored against
    the cluster by its best-combination MAC and takes the label of the cluster mode it resembles
    most (single MAC, weighted by ``freq_weight``), then nearest in frequency. Scores below
    ``min_mac`` count as zero in the assignment (so a poor pair cannot displace a good one) and such
    pairs are dropped: their test modes are reported unpaired.
    """
    X, A = np.asarray(phi_x), np.asarray(phi_a)
    fx, fa = np.asarray(f_x, dtype=float).ravel(), np.asarray(f_a, dtype=float).ravel()
    if X.ndim != 2 or A.ndim != 2 or X.shape[1] != fx.size or A.shape[1] != fa.size:
        raise ValueError("phi_x (n_dof, n_test), phi_a (n_dof, n_model) need one frequency per column")
    M = mac(X, A)
    S = M.copy()
    coef = {}
    groups = clusters(fa, close) if fa.size else []
    group_of = {j: g for g in groups for j in g}
    for g in groups:
        if len(g) < 2:
            continue
        for i in range(fx.size):
            val, u = subspace_mac(X[:, i], A[:, g])
            S[i, g] = val
            coef[(i, tuple(g))] = u
    in_cluster = np.zeros(fa.size, dtype=bool)
    for g in groups:
        in_cluster[g] = len(g) > 1
    df = np.abs(fa[None, :] - fx[:, None]) / np.abs(fx[:, None])
    cost = -np.where(S >= min_mac, S, 0.0) + freq_weight * (df - M * in_cluster)
    rows, cols = linear_sum_assignment(cost) if S.size else (np.zeros(0, int), np.zeros(0, int))
    pairs = []
    for i, j in zip(rows, cols):
        if S[i, j] < min_mac:
            continue
        g = tuple(group_of[j])
        u = coef.get((i, g), np.ones(1))
        pairs.append(Pair(int(i), int(j), float(fx[i]), float(fa[j]), float(M[i, j]), float(S[i, j]), g, u))
    pairs.sort(key=lambda p: p.test)
    paired_t = {p.test for p in pairs}
    paired_m = {p.model for p in pairs}
    return Pairing(pairs, M, [i for i in range(fx.size) if i not in paired_t],
                   [j for j in range(fa.size) if j not in paired_m])
