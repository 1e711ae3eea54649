"""Mode pairing by MAC (never by order), knowing what the test grid can tell apart: an optimal one-to-one
assignment with a minimum MAC and the frequency difference as tie-break.

* Close or repeated model modes (within ``close`` of each other in frequency) are paired through the best
  combination within their subspace (thesis eq. 3.15-3.18): a split test pair meets a repeated model pair.
* Model modes whose shapes look alike at the test DOFs (AutoMAC of the model at the test points, thesis
  eq. 2.3, at or above :data:`ALIAS_MAC`: spatial aliasing on a sparse grid) form one group with their
  close partners; a test mode is scored against the group by the best of its clusters, and within the
  group it is paired by frequency where the frequencies differ, since the grid cannot tell those shapes
  apart. The aliased pairs are reported (:meth:`Pairing.warnings`).
* A pair whose frequencies differ by more than ``limit`` (default :data:`FREQ_LIMIT`) is reported but
  not used for updating (``Pair.used``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linear_sum_assignment
from scipy.sparse.csgraph import connected_components

from .mac import automac, mac

#: AutoMAC at or above which two model modes are not told apart on the test grid
ALIAS_MAC = 0.8
#: relative frequency difference beyond which a pair is reported but not used for updating
FREQ_LIMIT = 0.30
#: weight of the single MAC against the squared frequency difference in choosing a cluster mode's label: it
#: decides within a cluster (frequencies 0.5 % apart: squared differences ~1e-4) and not across aliased
#: clusters (tens of percent apart)
LABEL_WEIGHT = 0.01


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


def clusters(f_a, rel_tol: float, sd=None) -> list:
    """Groups of mode indices whose frequencies chain within ``rel_tol`` of each other (relative), or,
    given each frequency's standard deviation ``sd``, within ``rel_tol`` standard deviations of their
    difference (:func:`.close_modes.close_groups`)."""
    f = np.asarray(f_a, dtype=float)
    if not f.size:
        return []
    order = np.argsort(f)
    fs = f[order]
    if sd is None:
        reach = rel_tol * np.maximum(np.abs(fs[1:]), np.abs(fs[:-1]))
    else:
        s = np.asarray(sd, dtype=float)[order]
        reach = rel_tol * np.hypot(s[1:], s[:-1])
    return [[int(i) for i in g] for g in np.split(order, np.flatnonzero(np.diff(fs) > reach) + 1)]


def aliased(groups, auto, alias: float) -> list:
    """The clusters ``groups`` joined where a mode of one and a mode of another have an AutoMAC ``auto`` at
    or above ``alias``: lists of cluster indices, chained (each list ascending, the lists in the order of
    their first cluster); a pair of clusters whose AutoMAC has an undefined (NaN) entry is not joined."""
    auto = np.asarray(auto)
    member = np.zeros((len(groups), auto.shape[0]))
    for k, g in enumerate(groups):
        member[k, g] = 1.0
    linked = (member @ (auto >= alias) @ member.T > 0.0) & (member @ np.isnan(auto) @ member.T == 0.0)
    _, label = connected_components(sp.csr_matrix(linked), directed=False)
    out: dict = {}
    for k in range(len(groups)):
        out.setdefault(label[k], []).append(k)
    return list(out.values())


@dataclass
class Pair:
    """One test mode paired with one model mode (or a combination of a cluster of close model modes).
    ``aliased``: the other model modes of its alias group (the grid cannot tell them from its own; paired
    by frequency among them); ``used``: within the frequency limit, so an update may use it."""

    test: int
    model: int
    f_test: float
    f_model: float
    mac: float
    mac_combined: float
    cluster: tuple = ()
    coefficients: np.ndarray = field(default_factory=lambda: np.ones(1))
    aliased: tuple = ()
    used: bool = True

    @property
    def df_pct(self) -> float:
        """(f_model - f_test) / f_test in percent."""
        return 100.0 * (self.f_model - self.f_test) / self.f_test


@dataclass
class Pairing:
    """Pairs, the MAC matrix (n_test, n_model), the test and model modes left unpaired, the AutoMAC of the
    model at the test DOFs (n_model, n_model), the aliased model modes [(j, k, AutoMAC)] (of different
    clusters, one of them paired) and the frequency limit (relative) beyond which a pair is not used."""

    pairs: list
    mac: np.ndarray
    unpaired_test: list
    unpaired_model: list
    automac: np.ndarray | None = None
    aliases: list = field(default_factory=list)
    limit: float = FREQ_LIMIT

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

    def warnings(self, f_model=None, beyond: bool = True) -> list:
        """What the pairing could not tell or did not use, in words: model modes that look alike at the test
        points (paired by frequency among them) and, with ``beyond``, pairs beyond the frequency limit
        (reported, not used for updating). ``f_model``: the model frequencies [Hz] to name."""
        def mode(j):
            return f"{j + 1}" + (f" ({f_model[j]:.1f} Hz)" if f_model is not None else "")

        out = [f"model modes {mode(j)} and {mode(k)} look alike at the test points (AutoMAC {a:.2f}): "
               "the test grid cannot tell them apart; their test modes are paired by frequency"
               for j, k, a in self.aliases]
        out += [f"test mode {p.test + 1} pairs with model mode {p.model + 1} at {p.df_pct:+.1f} %, beyond the "
                f"{100 * self.limit:.0f} % limit: reported, not used for updating"
                for p in self.pairs if beyond and not p.used]
        return out

    def to_dict(self) -> dict:
        """JSON-ready summary with 1-based mode numbers."""
        return {
            "pairs": [
                {"test_mode": p.test + 1, "model_mode": p.model + 1, "f_test_hz": p.f_test, "f_model_hz": p.f_model,
                 "df_pct": p.df_pct, "mac": p.mac_combined, "mac_single": p.mac,
                 "combined_with": [c + 1 for c in p.cluster if c != p.model],
                 "aliased_with": [c + 1 for c in p.aliased], "used": p.used}
                for p in self.pairs
            ],
            "unpaired_test_modes": [i + 1 for i in self.unpaired_test],
            "unpaired_model_modes": [j + 1 for j in self.unpaired_model],
            "aliases": [{"model_modes": [j + 1, k + 1], "automac": a} for j, k, a in self.aliases],
            "frequency_limit_pct": 100.0 * self.limit,
            "warnings": self.warnings(),
        }


def pair_modes(phi_x, phi_a, f_x, f_a, min_mac: float = 0.5, close: float = 0.005, freq_weight: float = 1e-3,
               alias: float = ALIAS_MAC, limit: float = FREQ_LIMIT) -> Pairing:
    """Pair test modes (columns of ``phi_x``) with model modes (``phi_a``, read at the same DOFs).

    Model modes within ``close`` (relative) of each other form a cluster, scored against a test mode by its
    best-combination MAC (eq. 3.18); clusters with modes whose AutoMAC reaches ``alias`` form a group,
    scored by its best cluster. The assignment (scipy's linear_sum_assignment) maximises the sum of these
    scores minus ``freq_weight`` times the squared relative frequency difference and, within a cluster, plus
    ``freq_weight`` LABEL_WEIGHT times the single MAC: between equal scores the label goes to the group's mode
    nearest in frequency (aliased modes, apart in frequency), and within a cluster, whose frequencies hardly
    differ, to the mode it resembles (a close pair whose shapes the grid tells apart). Scores below ``min_mac`` count as
    zero in the assignment (so a poor pair cannot displace a good one) and such pairs are dropped: their
    test modes are reported unpaired. Pairs more than ``limit`` apart in frequency are kept with
    ``used`` False.
    """
    X, A = np.asarray(phi_x), np.asarray(phi_a)
    fx, fa = np.asarray(f_x, dtype=float).ravel(), np.asarray(f_a, dtype=float).ravel()
    if X.ndim != 2 or A.ndim != 2 or X.shape[1] != fx.size or A.shape[1] != fa.size:
        raise ValueError("phi_x (n_dof, n_test), phi_a (n_dof, n_model) need one frequency per column")
    M = mac(X, A)
    auto = automac(A)
    groups = clusters(fa, close) if fa.size else []
    own = M.copy()  # each test mode against each model mode's own cluster
    coef = {}
    for g in groups:
        if len(g) > 1:
            for i in range(fx.size):
                val, coef[(i, tuple(g))] = subspace_mac(X[:, i], A[:, g])
                own[i, g] = val
    cluster_of = {j: tuple(g) for g in groups for j in g}
    S, group_of = own.copy(), {}
    for members in aliased(groups, auto, alias) if groups else []:
        cols = sorted(j for k in members for j in groups[k])
        S[:, cols] = own[:, cols].max(axis=1, keepdims=True)
        group_of.update({j: tuple(cols) for j in cols})
    in_cluster = np.array([len(cluster_of[j]) > 1 for j in range(fa.size)], dtype=bool)
    df = np.abs(fa[None, :] - fx[:, None]) / np.abs(fx[:, None])
    cost = -np.where(S >= min_mac, S, 0.0) + freq_weight * (df**2 - LABEL_WEIGHT * M * in_cluster)
    rows, cols = linear_sum_assignment(cost) if S.size else (np.zeros(0, int), np.zeros(0, int))
    pairs = []
    for i, j in zip(rows, cols):
        if S[i, j] < min_mac:
            continue
        g = cluster_of[j]
        pairs.append(Pair(int(i), int(j), float(fx[i]), float(fa[j]), float(M[i, j]), float(own[i, j]), g,
                          coef.get((i, g), np.ones(1)), tuple(k for k in group_of[j] if k not in g),
                          bool(df[i, j] <= limit)))
    pairs.sort(key=lambda p: p.test)
    paired_t = {p.test for p in pairs}
    paired_m = {p.model for p in pairs}
    aliases = [(j, k, float(auto[j, k])) for j in range(fa.size) for k in range(j + 1, fa.size)
               if auto[j, k] >= alias and cluster_of[j] != cluster_of[k] and (j in paired_m or k in paired_m)]
    return Pairing(pairs, M, [i for i in range(fx.size) if i not in paired_t],
                   [j for j in range(fa.size) if j not in paired_m], auto, aliases, limit)
