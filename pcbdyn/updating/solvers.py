"""Solvers for weighted updating equations A x = b (thesis chapter 4, section 7.3.1).

All solvers return a :class:`Solution` that carries the numerical rank, the epsilon-condition
number curve (eq. 4.21) and, when the problem is rank deficient, a plain message and the
undetermined parameter combinations (null space); a :class:`RankDeficiencyWarning` is issued too.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize as so

#: singular values below RTOL * sigma_1 are numerically zero
RTOL = 1e-8
#: a ratio sigma_r / sigma_{r+1} at least this large is a jump of the epsilon-condition curve
JUMP = 10.0


class RankDeficiencyWarning(UserWarning):
    """The updating equations do not determine every parameter."""


@dataclass
class Solution:
    """Result of one solve. ``x`` are the design variables (relative changes dp/p when the
    equations were built with ``p``)."""

    x: np.ndarray
    method: str
    rank: int
    singular_values: np.ndarray
    condition_curve: np.ndarray
    residual: float
    message: str = ""
    null_space: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    info: dict = field(default_factory=dict)

    @property
    def n_params(self) -> int:
        return self.x.size

    @property
    def rank_deficient(self) -> bool:
        return self.rank < self.n_params

    @property
    def condition_number(self) -> float:
        """Epsilon-condition number at the chosen rank, sigma_1 / sigma_rank (eq. 4.21)."""
        return float(self.condition_curve[self.rank - 1]) if self.rank else np.inf


def condition_curve(s) -> np.ndarray:
    """k2(A)|eps = sigma_1 / sigma_r for every trial rank r = 1..len(s) (thesis eq. 4.21, Fig. 4.1)."""
    s = np.asarray(s, float)
    with np.errstate(divide="ignore"):
        return np.where(s > 0, s[0] / np.where(s > 0, s, 1.0), np.inf)


def choose_rank(s, rtol: float = RTOL, jump: float = JUMP, rel_jump: float | None = None) -> int:
    """Numerical rank from singular values (descending), thesis eqs. 4.20-4.21.

    Values below ``rtol`` sigma_1 are zero. Then the largest step sigma_r / sigma_{r+1} of the
    epsilon-condition curve is a cut when it is at least ``jump`` (a decade by default) or, with
    ``rel_jump`` given, at least ``rel_jump`` times every other step (a jump that stands out of
    the curve, as the thesis reads Figs. 4.1 and 5.15a; meant for localisation, where dropping a
    noise-dominated direction is the point, rather than for the final solve).
    """
    s = np.asarray(s, float)
    if s.size == 0 or s[0] <= 0:
        return 0
    r0 = max(int(np.sum(s > rtol * s[0])), 1)
    if r0 > 1:
        ratios = s[: r0 - 1] / s[1:r0]
        k = int(np.argmax(ratios))
        others = np.delete(ratios, k)
        stands_out = rel_jump is not None and others.size and ratios[k] >= rel_jump * others.max()
        if ratios[k] >= jump or stands_out:
            return k + 1
    return r0


def _svd(A):
    A = np.asarray(A, float)
    if A.ndim != 2 or A.shape[0] == 0:
        raise ValueError(f"A has shape {A.shape}: need a 2-D matrix with at least one equation")
    U, s, Vt = np.linalg.svd(A, full_matrices=A.shape[0] < A.shape[1])  # square V always; U thin on tall A
    return U, s, Vt.T


def _rank_message(rank, n, m, null):
    if rank >= n:
        return ""
    combos = []
    for v in null.T[:3]:
        big = np.argsort(-np.abs(v))[:6]
        combos.append(" + ".join(f"{v[i]:+.3g}*x{i}" for i in big if abs(v[i]) > 1e-3))
    msg = (
        f"rank deficient: numerical rank {rank} < {n} parameters ({m} equations); "
        f"{n - rank} parameter combination(s) are not determined by the data, e.g. {'; '.join(combos)}. "
        "Hold or group parameters, add measurements or a perturbed configuration (PBC), or use subset selection."
    )
    warnings.warn(msg, RankDeficiencyWarning, stacklevel=3)
    return msg


def _finish(x, method, A, b, s, V, rank, **info):
    n = A.shape[1]
    null = V[:, rank:n] if rank < n else np.zeros((n, 0))
    s_full = np.zeros(n)
    s_full[: s.size] = s[:n]
    return Solution(
        x=x,
        method=method,
        rank=rank,
        singular_values=s_full,
        condition_curve=condition_curve(s_full),
        residual=float(np.linalg.norm(A @ x - b)),
        message=_rank_message(rank, n, A.shape[0], null),
        null_space=null,
        info=info,
    )


def solve_ls(A, b, rank: int | None = None, rtol: float = RTOL, jump: float = JUMP) -> Solution:
    """Truncated-SVD least squares (thesis eqs. 4.18-4.21): minimum-norm solution on the
    numerical rank (given, or chosen from the jump of the epsilon-condition curve)."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    U, s, V = _svd(A)
    r = choose_rank(s, rtol, jump) if rank is None else int(rank)
    x = V[:, :r] @ ((U[:, :r].T @ b) / s[:r])
    return _finish(x, "ls", A, b, s, V, r)


def solve_tls(
    A, b, rank: int | None = None, t_b: float | None = None, precision_ratio: float = 1.0,
    rtol: float = RTOL, jump: float = JUMP,
) -> Solution:
    """Total least squares (thesis eqs. 4.33-4.37) on C = [A, t_b b].

    ``t_b``: column weight of b (default eq. 4.43 with ``precision_ratio`` = k_A / k_b). The rank
    of A (given or chosen as in :func:`choose_rank`) truncates the SVD of C; with full rank this is
    the classical TLS solution x = -V12 / (V22 t_b), otherwise the minimum-norm truncated TLS
    solution -V12 V22^T / (||V22||^2 t_b) over the discarded right singular vectors.
    """
    from .weighting import tls_column_weight

    A, b = np.asarray(A, float), np.asarray(b, float)
    m, n = A.shape
    _, sA, VA = _svd(A)
    r = choose_rank(sA, rtol, jump) if rank is None else int(rank)
    t = tls_column_weight(A, b, precision_ratio) if t_b is None else float(t_b)
    _, sC, VC = _svd(np.column_stack([A, t * b]))
    V12, V22 = VC[:n, r:], VC[n, r:]
    nv = float(V22 @ V22)
    if nv < 1e-24:
        raise np.linalg.LinAlgError(
            "no TLS solution: b is orthogonal to the retained space of [A b] (V22 = 0); use solve_ls"
        )
    x = -(V12 @ V22) / nv / t
    generic = r < n or m <= n or sA[n - 1] > (sC[n] if sC.size > n else 0.0)
    return _finish(x, "tls", A, b, sA, VA, r, t_b=t, unique=bool(generic))


def bayes_alpha(iteration: int, alpha0: float = 0.5, factor: float = 0.9) -> float:
    """Bayesian weight schedule: 0.5 at the first iteration, times 0.9 at each next (thesis eq. 4.40)."""
    return alpha0 * factor**iteration


def solve_bayes(A, b, alpha: float = 0.5, rtol: float = RTOL, jump: float = JUMP) -> Solution:
    """Bayesian estimate with the prior x0 = 0 (thesis eqs. 4.38-4.39):
    (A^T A + alpha G) x = A^T b, G = diag(A^T A) (beta_j^2 of eq. 4.40). The rank of A is still
    reported: the prior makes x unique, but undetermined combinations simply stay at zero."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    _, s, V = _svd(A)
    r = choose_rank(s, rtol, jump)
    N = A.T @ A
    x = np.linalg.solve(N + alpha * np.diag(np.diag(N)), A.T @ b)
    return _finish(x, "bayes", A, b, s, V, r, alpha=alpha)


def solve_bounded(
    A, b, lower, upper, ridge: float | None = None, rtol: float = RTOL, jump: float = JUMP
) -> Solution:
    """Bound-constrained least squares, the quadratic programme of thesis eqs. 4.44-4.48
    (scipy.optimize.lsq_linear). When A is rank deficient, ||ridge x||^2 is added (eq. 4.46) so the
    minimiser is unique; the default ridge is 1e-6 sigma_1, which only acts on undetermined
    directions. ``lower``/``upper`` bound x (relative changes: p_min/p - 1, p_max/p - 1)."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    n = A.shape[1]
    lower = np.broadcast_to(np.asarray(lower, float), (n,))
    upper = np.broadcast_to(np.asarray(upper, float), (n,))
    if np.any(lower > upper):
        raise ValueError("bounds: every lower bound must be <= its upper bound")
    _, s, V = _svd(A)
    r = choose_rank(s, rtol, jump)
    mu = (1e-6 * s[0] if r < n else 0.0) if ridge is None else float(ridge)
    x = bounded_lsq(A, b, lower, upper, mu)
    active = np.flatnonzero((x <= lower + 1e-12) | (x >= upper - 1e-12))
    return _finish(x, "bounded", A, b, s, V, r, active_bounds=active, ridge=mu)


def bounded_lsq(A, b, lower, upper, ridge: float = 0.0) -> np.ndarray:
    """x minimising ||A x - b||^2 + ||ridge x||^2 with lower <= x <= upper (eqs. 4.44-4.48): the step of
    every bounded fit (:func:`solve_bounded`, :func:`.gauss_newton.gauss_newton`)."""
    A, b = np.asarray(A, float), np.asarray(b, float)
    n = A.shape[1]
    if ridge > 0:
        A, b = np.vstack([A, ridge * np.eye(n)]), np.concatenate([b, np.zeros(n)])
    return so.lsq_linear(A, b, bounds=(lower, upper), method="bvls", tol=1e-12).x


def covariance(J, r, stated: bool = True) -> np.ndarray:
    """Covariance of least-squares estimates with Jacobian ``J`` (n_rows, k) at residual ``r``:
    (J^T J)^+ times the residual variance s^2 = |r|^2 / (n - k). Rows in units of a ``stated`` noise
    (chi-square weights, eq. 4.28) keep at least that noise (s^2 >= 1: a fit better than the noise
    does not make the estimates surer than it); unweighted rows take s^2 as it is. The pseudo-inverse
    is taken with the columns scaled to unit length: columns in SI units of unlike quantities (ln E
    beside a stiff spring in N/m, 1e-8 of it) would otherwise read as a rank the pseudo-inverse drops,
    and report a standard deviation of zero for the magnitude the data know least."""
    J = np.asarray(J, float)
    n, k = J.shape
    if k == 0:
        return np.zeros((0, 0))
    s2 = float(np.asarray(r, float) @ np.asarray(r, float)) / max(n - k, 1)
    norms = np.linalg.norm(J, axis=0)
    d = np.divide(1.0, norms, out=np.zeros(k), where=norms > 0)
    Js = J * d
    return (max(1.0, s2) if stated else s2) * (d[:, None] * np.linalg.pinv(Js.T @ Js) * d[None, :])


def line_search(residue, beta_max: float = 2.0, tol: float = 1e-4):
    """beta minimising residue(beta), the overall frequency residue of p + beta dp (thesis eq. 7.6),
    searched on [0, beta_max]. Returns (beta, residue(beta))."""
    res = so.minimize_scalar(residue, bounds=(0.0, beta_max), method="bounded", options={"xatol": tol})
    r0 = residue(0.0)
    return (float(res.x), float(res.fun)) if res.fun < r0 else (0.0, float(r0))


def frequency_residue(f_a, f_x) -> float:
    """Overall frequency residue sigma = sqrt(mean((1 - f_a / f_x)^2)) (thesis eqs. 7.4, 7.6)."""
    f_a, f_x = np.asarray(f_a, float), np.asarray(f_x, float)
    return float(np.sqrt(np.mean((1.0 - f_a / f_x) ** 2)))


SOLVERS = {"ls": solve_ls, "tls": solve_tls, "bayes": solve_bayes, "bounded": solve_bounded}
