"""Parameter-oriented error localisation by subset selection (thesis section 5.2).

All functions take weighted equations A x = b whose unknowns are relative parameter changes
(columns weighted by the parameter values, eq. 4.41; rows weighted, eq. 4.42 or 4.28).

- :func:`qr_basic_solution`: QR with column pivoting, basic solution (eqs. 5.26-5.33);
- :func:`svd_qr`: SVD rank estimate + QR pivoting on the leading right singular vectors (5.2.2);
- :func:`tls_qrf`: TLS regularising/condensing (5.37-5.50), forward selection by the cos^2
  criterion with Householder steps (5.51-5.54), backward exclusion by the residue descending
  ratio (5.55-5.62) and exclusion by the subset solution threshold (5.63-5.64), with the
  section 5.2.3 check that the parameters can explain the data at all.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from .solvers import JUMP, RTOL, choose_rank, condition_curve
from .weighting import tls_column_weight

#: 5.2.3 check: b counts as explained when its part outside range(A) is below this fraction of ||b||
EXPLAIN_TOL = 0.1


@dataclass
class Subset:
    """A localisation result. Indices refer to columns of A (parameters)."""

    method: str
    selected: np.ndarray
    x: np.ndarray
    rank: int
    condition_curve: np.ndarray
    order: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    descending_ratio: np.ndarray = field(default_factory=lambda: np.zeros(0))
    retained: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    solution: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rank_Ab: int = 0
    out_of_range: float = 0.0
    explains_data: bool = True
    message: str = ""


def threshold_selection(y, floor: float = 0.01, fraction: float = 0.2) -> np.ndarray:
    """Indices whose relative change |y_i| exceeds max(floor, fraction * max|y|) (thesis eqs. 5.63-5.64)."""
    y = np.asarray(y, float)
    if y.size == 0:
        return np.zeros(0, int)
    return np.flatnonzero(np.abs(y) > max(floor, fraction * np.max(np.abs(y))))


def _lstsq_subset(A, b, cols):
    x = np.zeros(A.shape[1])
    if len(cols):
        x[cols] = np.linalg.lstsq(A[:, cols], b, rcond=None)[0]
    return x


def _rank(A, rank, rtol, jump):
    s = np.linalg.svd(A, compute_uv=False)
    s_full = np.zeros(A.shape[1])
    s_full[: s.size] = s[: A.shape[1]]
    r = choose_rank(s, rtol, jump) if rank is None else int(rank)
    return r, s_full


def qr_basic_solution(A, b, rank: int | None = None, rtol: float = RTOL, jump: float = JUMP) -> Subset:
    """Basic solution of QR with column pivoting (thesis eqs. 5.26-5.33): the first r pivoted
    columns solve the equations, the others are zero. b plays no part in the choice."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    r, s = _rank(A, rank, rtol, jump)
    Q, R, piv = sla.qr(A, mode="economic", pivoting=True)
    c = Q.T @ b
    x = np.zeros(A.shape[1])
    x[piv[:r]] = sla.solve_triangular(R[:r, :r], c[:r])
    return Subset("qr", np.sort(piv[:r]), x, r, condition_curve(s), order=piv[:r], solution=x.copy())


def svd_qr(A, b, rank: int | None = None, rtol: float = RTOL, jump: float = JUMP) -> Subset:
    """SVD/QR subset selection (thesis section 5.2.2): QR with column pivoting on the r leading
    right singular vectors picks r "sufficiently independent" columns; LS on them. ``selected``
    applies the threshold of eq. 5.64 to that solution."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    r, s = _rank(A, rank, rtol, jump)
    _, _, Vt = np.linalg.svd(A)
    _, _, piv = sla.qr(Vt[:r, :], pivoting=True)
    cols = piv[:r]
    x = _lstsq_subset(A, b, cols)
    return Subset("svd/qr", threshold_selection(x), x, r, condition_curve(s), order=cols, retained=cols, solution=x)


def _householder(x):
    """v, beta with (I - beta v v^T) x = -sign(x0) ||x|| e1."""
    v = x.astype(float).copy()
    nx = np.linalg.norm(x)
    if nx == 0:
        return v, 0.0
    v[0] += np.copysign(nx, x[0]) if x[0] != 0 else nx
    return v, 2.0 / (v @ v)


def qrf_forward(W, w, n_max: int | None = None, tol: float = 1e-10):
    """Forward selection by the cos^2 criterion (thesis eqs. 5.51-5.54): at each step take the
    column whose remaining part (below the rows already used) is most parallel to the remaining
    right side, then zero its sub-diagonal with a Householder reflection applied to W and w.
    Stops when the remaining right side vanishes (relative ``tol``) or after ``n_max`` columns.
    Returns the selection order (column indices)."""
    W, w = np.array(W, float), np.array(w, float)
    m, n = W.shape
    n_max = min(m, n) if n_max is None else min(n_max, m, n)
    p = np.arange(n)
    c0 = np.einsum("ij,ij->j", W, W)
    w0 = np.linalg.norm(w)
    r = 0
    while r < n_max and np.linalg.norm(w[r:]) > tol * w0:
        cr = np.einsum("ij,ij->j", W[r:, r:], W[r:, r:])
        ok = cr > 1e-12 * c0[p[r:]]
        if not np.any(ok):
            break
        cos2 = np.where(ok, (w[r:] @ W[r:, r:]) ** 2 / np.where(ok, cr, 1.0), 0.0) / (w[r:] @ w[r:])
        k = r + int(np.argmax(cos2))
        if cos2[k - r] <= tol**2:
            break
        W[:, [r, k]] = W[:, [k, r]]
        p[[r, k]] = p[[k, r]]
        v, beta = _householder(W[r:, r])
        W[r:, r:] -= beta * np.outer(v, v @ W[r:, r:])
        w[r:] -= beta * v * (v @ w[r:])
        r += 1
    return p[:r]


def descending_ratios(M, rhs):
    """Relative residue function Rr_i (eq. 5.59) and descending ratios dRr_i (eq. 5.60) of the
    columns of M taken in order: QR of M, br = Q^T rhs, Rr_i = ||br_{i+1:}|| / ||br|| * 100."""
    Q, _ = np.linalg.qr(M, mode="complete")
    br = Q.T @ rhs
    tail = np.sqrt(np.cumsum((br**2)[::-1])[::-1])
    Rr = 100.0 * np.append(tail, 0.0)[: M.shape[1] + 1] / np.linalg.norm(br)
    return Rr, Rr[:-1] - Rr[1:]


def tls_qrf(
    A, b, rank: int | None = None, alpha: float = 0.8, t_b: float | None = None,
    precision_ratio: float = 1.0, floor: float = 0.01, fraction: float = 0.2,
    rtol: float = RTOL, jump: float = JUMP, rel_jump: float | None = None, explain_tol: float = EXPLAIN_TOL,
) -> Subset:
    """TLS/QR-F error localisation (thesis section 5.2.3).

    1. n1 = numerical rank of A (given, or from the epsilon-condition curve, see
       :func:`~pcbdyn.updating.solvers.choose_rank` for ``rtol``/``jump``/``rel_jump``); SVD of
       C = [A, t_b b] (t_b from eq. 4.43), W = V^T; W11 = W[:n1, :n], W12 = W[:n1, n] (5.41-5.50).
    2. Forward selection on W11 y = W12 by cos^2 with Householder steps (5.51-5.54).
    3. Backward exclusion: QR of Sigma1 W11 on the selected columns in selection order, residue
       descending ratios dRr_i; trailing parameters with dRr_i < alpha * 100 / n1 are dropped
       (5.55-5.62).
    4. LS on the retained columns of the original A x = b; parameters with |x_i| below
       max(floor, fraction max|x|) are excluded (5.63-5.64).

    The 5.2.3 check: if b has a part outside range(A) (rank n1) larger than ``explain_tol`` ||b||,
    the numerical rank of [A b] exceeds that of A and the chosen parameters cannot explain the
    data: ``explains_data`` is False and ``message`` says so.
    """
    A, b = np.asarray(A, float), np.asarray(b, float)
    m, n = A.shape
    UA, sA, VtA = np.linalg.svd(A, full_matrices=False)
    n1 = choose_rank(sA, rtol, jump, rel_jump) if rank is None else int(rank)
    s_full = np.zeros(n)
    s_full[: sA.size] = sA[:n]
    t = tls_column_weight(A, b, precision_ratio) if t_b is None else float(t_b)
    C = np.column_stack([A, t * b])
    _, sC, VtC = np.linalg.svd(C, full_matrices=C.shape[0] < C.shape[1])
    W11, W12 = VtC[:n1, :n], VtC[:n1, n]
    order = qrf_forward(W11, W12, n_max=n1)
    S1 = np.zeros(n1)
    S1[: min(n1, sC.size)] = sC[:n1]
    Rr, dRr = descending_ratios(S1[:, None] * W11[:, order], S1 * W12)
    keep = np.flatnonzero(dRr >= alpha * 100.0 / n1)
    nb = keep[-1] + 1 if keep.size else 0
    retained = order[:nb]
    solution = _lstsq_subset(A, b, retained)
    selected = retained[np.isin(retained, retained[threshold_selection(solution[retained], floor, fraction)])]
    x = _lstsq_subset(A, b, selected)

    Ur = UA[:, :n1]
    out = float(np.linalg.norm(b - Ur @ (Ur.T @ b)) / np.linalg.norm(b))
    explains = out <= explain_tol
    rank_Ab = n1 + (0 if explains else 1)
    msg = "" if explains else (
        f"rank([A b]) = {rank_Ab} > rank(A) = {n1}: {100 * out:.1f} % of b lies outside the range of "
        "the parameters' sensitivities; these parameters cannot explain the data (a model error is "
        "elsewhere or of another kind)"
    )
    return Subset(
        "tls/qr-f", np.sort(selected), x, n1, condition_curve(s_full), order=order, descending_ratio=dRr,
        retained=retained, solution=solution, rank_Ab=rank_Ab, out_of_range=out, explains_data=explains,
        message=msg,
    )


def explain_tol_from_noise(A, b, redraws) -> float:
    """The 5.2.3 check's tolerance for a stated noise: twice the part of b's noise outside
    range(A), relative to ||b|| (rms over ``redraws``, equations rebuilt with that noise drawn
    again), and never below :data:`EXPLAIN_TOL`: noise alone must not make the parameters look
    unable to explain the data."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    U = np.linalg.svd(A, full_matrices=False)[0]
    out = [np.asarray(bd, float) - b for _, bd in redraws]
    out = [d - U @ (U.T @ d) for d in out]
    return max(EXPLAIN_TOL, 2.0 * float(np.sqrt(np.mean([d @ d for d in out])) / np.linalg.norm(b)))
