"""Test design on plain arrays: where to put sensors, where to excite, where to hang a free structure, and
which perturbed configurations to add (thesis ch. 6) so that the updating equations determine the
parameters.

- Sensors: Effective Independence (Kammer's EfI: remove, one at a time, the candidate whose loss
  lowers det(Phi^T Phi) least; a triaxial sensor is a group of rows removed together, its share of
  the determinant det(I - Phi_g F^-1 Phi_g^T)), then an exchange that raises the determinant further
  while the largest off-diagonal AutoMAC (thesis eq. 2.3 on the chosen rows) stays under a bound.
- Exciter: the driving-point share of each mode (|phi| over the mode's largest |phi| among the
  candidates); the best point is the one whose smallest share over the target modes is largest.
- Suspension: points near the nodal lines of the lowest modes, and the spring stiffness that puts the
  rigid-body (suspension) modes at a stated share of the first elastic one.
- Configurations: D-optimal choice (greatest log det of the stacked Fisher information A^T A of the
  noise-weighted equations, thesis eq. 6.4) of K candidate blocks added to the base one.

Nothing here builds a model: rows of mode shapes and equation blocks come from :mod:`pcbdyn.problems`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: improvements of log det below this are not exchanges worth making
_LD_TOL = 1e-9


def log_det(F) -> float:
    """log det F of a symmetric positive (semi-)definite matrix; -inf when it is singular."""
    sign, ld = np.linalg.slogdet(np.asarray(F, float))
    return float(ld) if sign > 0 else -np.inf


def _log_dets(Fs) -> np.ndarray:
    sign, ld = np.linalg.slogdet(Fs)
    return np.where(sign > 0, ld, -np.inf)


def automac_offdiag(G) -> np.ndarray:
    """Largest off-diagonal AutoMAC of the Gram matrices ``G`` (..., m, m) = Phi^T Phi of real shapes
    (MAC_ij = G_ij^2 / (G_ii G_jj), thesis eq. 2.3); 0 for one mode."""
    G = np.asarray(G, float)
    d = np.diagonal(G, axis1=-2, axis2=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mac = G**2 / (d[..., :, None] * d[..., None, :])
    m = G.shape[-1]
    mac = np.where(np.eye(m, dtype=bool), 0.0, np.nan_to_num(mac, nan=1.0))
    return mac.max(axis=(-2, -1)) if m > 1 else np.zeros(G.shape[:-2])


def _group_blocks(Phi, groups):
    """(group ids, per group the rows (n_groups, r, m)); every group must have the same row count r."""
    Phi = np.asarray(Phi, float)
    groups = np.arange(Phi.shape[0]) if groups is None else np.asarray(groups)
    ids, inverse, counts = np.unique(groups, return_inverse=True, return_counts=True)
    if np.any(counts != counts[0]):
        raise ValueError("groups: every sensor must have the same number of rows (directions)")
    order = np.argsort(inverse, kind="stable")
    return ids, Phi[order].reshape(ids.size, counts[0], Phi.shape[1])


def effective_independence(Phi, n_keep: int, groups=None) -> np.ndarray:
    """Indices (into the sorted unique ``groups``; rows when None) of the ``n_keep`` sensors Effective
    Independence keeps from the candidate rows ``Phi`` (n_rows, m): greedy elimination of the sensor
    whose removal keeps the largest share det(I - Phi_g F^-1 Phi_g^T) of det F, F = Phi^T Phi over the
    sensors left (for one row, 1 - E_D, E_D the EfI value)."""
    _, B = _group_blocks(Phi, groups)
    n, r, m = B.shape
    if n_keep * r < m:
        raise ValueError(f"{n_keep} sensors of {r} direction(s) cannot tell {m} modes apart: give at least "
                         f"{-(-m // r)} sensors or fewer modes")
    if n_keep > n:
        raise ValueError(f"{n_keep} sensors asked for but only {n} candidates")
    keep = np.arange(n)
    F = np.einsum("gri,grj->ij", B, B)
    if not np.isfinite(log_det(F)):
        raise ValueError("the candidates do not see every target mode (Phi^T Phi is singular): add candidates or "
                         "drop modes")
    while keep.size > n_keep:
        Bk = B[keep]
        E = np.einsum("gri,ij,gsj->grs", Bk, np.linalg.inv(F), Bk)
        share = np.linalg.det(np.eye(r)[None] - E)
        k = int(np.argmax(share))
        F = F - Bk[k].T @ Bk[k]
        keep = np.delete(keep, k)
    return keep


@dataclass
class SensorSet:
    """Chosen sensors (indices into the candidate groups), log det(Phi^T Phi) of their rows, that of
    plain EfI's set, and the largest off-diagonal AutoMAC of the chosen rows."""

    chosen: np.ndarray
    log_det: float
    efi_log_det: float
    automac_max: float


def choose_sensors(Phi, n_keep: int, groups=None, max_automac: float = 0.25, max_passes: int = 200) -> SensorSet:
    """EfI (:func:`effective_independence`), then exchanges of one chosen sensor for one candidate: while
    the largest off-diagonal AutoMAC exceeds ``max_automac`` the exchange that lowers it most, then those
    that raise log det(Phi^T Phi) most without breaking the bound (steepest ascent, until none helps).
    The AutoMAC bound is a guard on the set, not a guarantee: when no exchange brings it under the bound,
    the value reached becomes the bound of the log det exchanges, and the result reports it."""
    _, B = _group_blocks(Phi, groups)
    G_all = np.einsum("gri,grj->gij", B, B)
    chosen = effective_independence(Phi, n_keep, groups)
    efi = log_det(G_all[chosen].sum(axis=0))
    bound = max_automac
    for _ in range(max_passes):
        G = G_all[chosen].sum(axis=0)
        ld, am = log_det(G), float(automac_offdiag(G))
        over = max(am - bound, 0.0)
        others = np.setdiff1d(np.arange(B.shape[0]), chosen)
        best = None
        for pos, g in enumerate(chosen):
            trial = (G - G_all[g])[None] + G_all[others]
            lds, ams = _log_dets(trial), automac_offdiag(trial)
            overs = np.maximum(ams - bound, 0.0)
            if over > 0:
                gain = np.where(np.isfinite(lds), over - overs, -np.inf)
                ok = gain > 1e-12
            else:
                gain = np.where(overs > 0, -np.inf, lds - ld)
                ok = gain > _LD_TOL
            if ok.any():
                h = int(np.argmax(np.where(ok, gain, -np.inf)))
                if best is None or gain[h] > best[0]:
                    best = (gain[h], pos, others[h])
        if best is None and over > 0:
            bound = am + 1e-12  # the guard cannot be met: keep what was reached, raise the determinant
            continue
        if best is None:
            break
        chosen = np.sort(np.r_[np.delete(chosen, best[1]), best[2]])
    G = G_all[chosen].sum(axis=0)
    return SensorSet(chosen, log_det(G), efi, float(automac_offdiag(G)))


def driving_point_shares(Phi) -> np.ndarray:
    """(n_rows, m): |phi| at each candidate row over the mode's largest |phi| among the rows: how much of
    its best excitation a unit force there gives each mode (a driving-point residue phi^2 is the square
    of this times the mode's largest)."""
    A = np.abs(np.asarray(Phi, float))
    big = A.max(axis=0)
    return A / np.where(big > 0, big, 1.0)


def best_exciter(Phi, usable=None) -> tuple:
    """(row, its share of each mode): the usable candidate row whose smallest share
    (:func:`driving_point_shares`) over the modes is largest, i.e. the point farthest from every mode's
    nodal lines."""
    S = driving_point_shares(Phi)
    worst = S.min(axis=1)
    if usable is not None:
        worst = np.where(np.asarray(usable, bool), worst, -1.0)
    j = int(np.argmax(worst))
    return j, S[j]


def nodal_score(Phi) -> np.ndarray:
    """Per candidate row, the largest share (:func:`driving_point_shares`) over the modes of ``Phi``: small
    near the nodal lines of every one of them (where a suspension touches them least)."""
    return driving_point_shares(Phi).max(axis=1)


def spring_share(rigid_rows) -> np.ndarray:
    """Eigenvalues of R^T R for ``rigid_rows`` R (n_springs, n_rigid): the mass-normalised rigid-body
    modes read at the springs along their lines; unit springs there give suspension modes of
    omega^2 = these (Rayleigh-Ritz on the rigid-body modes, exact while the springs leave the elastic
    modes alone)."""
    R = np.asarray(rigid_rows, float)
    return np.sort(np.linalg.eigvalsh(R.T @ R))


def spread_points(score, rigid_rows, n_points: int, share: float = 0.25) -> np.ndarray:
    """``n_points`` rows to hang a structure by: among the candidates whose ``score`` (:func:`nodal_score`)
    is in the lowest ``share`` of them, greedily the ones that make the springs hold the rigid-body
    motions they can reach best (the largest smallest non-zero eigenvalue of R^T R, ties to the lower
    score). ``rigid_rows``: (n_rows, n_rigid)."""
    score = np.asarray(score, float)
    R = np.asarray(rigid_rows, float)
    pool = np.argsort(score)[:max(n_points, int(np.ceil(share * score.size)))]
    chosen = [int(pool[0])]
    reach = np.linalg.matrix_rank(R[pool].T @ R[pool])
    while len(chosen) < n_points:
        best, key = None, None
        for j in pool:
            if j in chosen:
                continue
            ev = spring_share(R[chosen + [int(j)]])
            k = min(len(chosen) + 1, reach)
            kk = (ev[-k:][0], -score[j])
            if key is None or kk > key:
                best, key = int(j), kk
        chosen.append(best)
    return np.array(chosen)


def fisher(blocks) -> np.ndarray:
    """sum_c A_c^T A_c of noise-weighted equation blocks A_c (rows in units of their noise): the
    information the stacked equations (thesis eq. 6.4) carry about x = dp/p."""
    return sum(np.asarray(A, float).T @ np.asarray(A, float) for A in blocks)


def predicted_std(F) -> np.ndarray:
    """1-sigma of each x = dp/p from the information ``F``: sqrt(diag F^-1); inf for a parameter the
    information leaves undetermined (a direction of F's null space that moves it)."""
    F = np.asarray(F, float)
    w, V = np.linalg.eigh(F)
    small = w <= 1e-12 * max(float(w.max()), 1e-300)
    var = (V[:, ~small] ** 2) @ (1.0 / w[~small])
    undetermined = np.any(np.abs(V[:, small]) > 1e-6, axis=1)
    return np.where(undetermined, np.inf, np.sqrt(var))


def d_optimal(F0, candidates, k: int, groups=None, max_passes: int = 100) -> np.ndarray:
    """Indices of the ``k`` candidate informations (``candidates`` (n, p, p)) whose sum with the base
    ``F0`` has the largest log det (D-optimal design): greedy additions, then exchanges of a chosen one
    for another while that raises log det. ``groups`` (n,): at most one candidate of a group is chosen
    (one added mass per place). A ridge of 1e-9 of the mean diagonal makes a base that determines
    nothing comparable."""
    Fc = np.asarray(candidates, float)
    n, p, _ = Fc.shape
    groups = np.arange(n) if groups is None else np.asarray(groups)
    if not 0 < k <= np.unique(groups).size:
        raise ValueError(f"{k} configurations asked for from {np.unique(groups).size} candidate places")
    ridge = 1e-9 * max(float(np.mean(np.trace(Fc, axis1=1, axis2=2))) / p, 1e-300) * np.eye(p)
    base = np.asarray(F0, float) + ridge

    def best_addition(S, others):
        ld = _log_dets(S[None] + Fc)
        ld[np.isin(groups, groups[others])] = -np.inf
        h = int(np.argmax(ld))
        return h, ld[h]

    chosen: list = []
    for _ in range(k):
        chosen.append(best_addition(base + Fc[chosen].sum(axis=0), chosen)[0])
    for _ in range(max_passes):
        S = base + Fc[chosen].sum(axis=0)
        cur, best = log_det(S), None
        for pos, c in enumerate(chosen):
            h, ld = best_addition(S - Fc[c], chosen[:pos] + chosen[pos + 1:])
            if ld > cur + _LD_TOL and (best is None or ld > best[0]):
                best = (ld, pos, h)
        if best is None:
            break
        chosen[best[1]] = best[2]
    return np.array(chosen)
