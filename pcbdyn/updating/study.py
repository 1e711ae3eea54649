"""Success-ratio studies of parameter error localisation (thesis sections 5.3-5.4, 6.4.2).

A *case* knows its parameters, its true errors and how to build weighted updating equations
A x = b from noisy simulated test data (:meth:`SimulatedFreePCB.equations`). :func:`run_study`
localises over noise levels x random shots x methods x equation types, in parallel processes,
and returns one row per localisation; :func:`summarise` gives the mean and standard deviation of
the success ratio (eq. 5.66) per equation type, method and noise level.

Methods (all see the same noisy equations of a shot):

- ``tls-qrf``: :func:`~.subset.tls_qrf` (thesis 5.2.3), b weighted for TLS (eq. 4.43) by the
  errors the stated noise level makes in A and b, measured by drawing that noise again on the
  shot's data (:func:`~.weighting.tls_column_weight_from_noise`): the study states the level,
  as a tester states the precision of a measurement;
- ``svd-qr``: :func:`~.subset.svd_qr` (5.2.2);
- ``qr``: :func:`~.subset.qr_basic_solution` with the threshold of eq. 5.64;
- ``min-norm``: the minimum-norm LS solution of all parameters at the full numerical rank (only
  singular values below RTOL sigma_1 are dropped; no epsilon-condition cut and never the chosen
  ``rank``: "for minimal 2-norm method, the numerical rank number is always set to 18", thesis
  5.4.1, QMS), judged by the same threshold as the others (eq. 5.64: |x_i| above
  max(0.01, 0.2 max|x|)). This is how the thesis counts N_det of its "minimal 2-norm" solution
  (section 5.4.1: 16 of 18 moduli detected).
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from ..parallel import run_jobs
from ..testdata.noise import add_noise
from .solvers import RankDeficiencyWarning, solve_ls
from .subset import qr_basic_solution, svd_qr, threshold_selection, tls_qrf
from .success import success_ratio, success_statistics
from .weighting import NOISE_REDRAWS, tls_column_weight_from_noise, unit_row_weights, weight_rows

METHODS = ("tls-qrf", "svd-qr", "qr", "min-norm")


def _rank(rank, n):
    """None: automatic; k >= 0: k; k < 0: n + k (e.g. -1 = one below full, the thesis' free PCB)."""
    if rank is None:
        return None
    return int(rank) if rank >= 0 else n + int(rank)


def localise(method: str, A, b, rank: int | None = None, t_b: float | None = None) -> np.ndarray:
    """Indices of the parameters ``method`` (see the module doc) detects as erroneous; ``t_b``:
    TLS weight of b (default eq. 4.43 with k_A = k_b)."""
    r = _rank(rank, A.shape[1])
    if method == "tls-qrf":
        return tls_qrf(A, b, rank=r, t_b=t_b).selected
    if method == "svd-qr":
        return svd_qr(A, b, rank=r).selected
    if method == "qr":
        return threshold_selection(qr_basic_solution(A, b, rank=r).x)
    if method == "min-norm":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RankDeficiencyWarning)
            # full numerical rank (thesis 5.4.1): no jump of the epsilon-condition curve is cut
            return threshold_selection(solve_ls(A, b, jump=np.inf).x)
    raise ValueError(f"method {method!r}: choose one of {', '.join(METHODS)}")


def compress(A, b):
    """(R[:, :n], R[:, n]) from the QR factorisation [A b] = Q R: n + 1 rows that keep every
    quantity the localisation methods use (singular values and right singular vectors of A and
    of [A b], ||A||_F, ||b||, least-squares solutions, the part of b outside range(A)), so tall
    FRF blocks cost no more than small ones."""
    if A.shape[0] <= A.shape[1] + 1:
        return A, b
    R = np.linalg.qr(np.column_stack([A, b]), mode="r")
    return R[:, :-1], R[:, -1]


def unit_weighted(blk):
    """Unit-row-weighted equations (eq. 4.42) without the all-zero rows (e.g. the imaginary
    rows of undamped FRF equations)."""
    keep = np.linalg.norm(blk.A, axis=1) > 0
    A, b = blk.A[keep], blk.b[keep]
    return weight_rows(A, b, unit_row_weights(A))


class StudyCase:
    """What :func:`run_study` asks of a case (:mod:`pcbdyn.problems.cases`): ``parameter_names``,
    ``true_errors`` (indices), ``kinds`` (equation types), ``measure`` (noisy test data) and ``build``
    (weighted equations from data), hence ``equations``."""

    def equations(self, kind: str, level_pct: float, rng):
        """Weighted (A, b) of equation type ``kind`` from test data with ``level_pct`` % uniform
        noise (eqs. 5.72-5.74)."""
        return self.build(kind, self.measure(kind, level_pct, rng))


def _run_batch(kind, level, shots, methods, seed, rank, case):
    """The rows of ``shots`` of one equation type and noise level (see :func:`run_study`)."""
    rows = []
    for shot in shots:
        key = [seed, case.kinds.index(kind), int(round(level * 1e6)), shot]
        data = case.measure(kind, level, np.random.default_rng(key))
        A, b = case.build(kind, data)
        t_b = None
        if "tls-qrf" in methods:
            redraw = np.random.default_rng(key + [1])
            t_b = tls_column_weight_from_noise(A, b, [
                case.build(kind, tuple(add_noise(d, level, redraw) for d in data)) for _ in range(NOISE_REDRAWS)])
        A, b = compress(A, b)
        for method in methods:
            sel = localise(method, A, b, rank, t_b)
            rows.append({
                "equations": kind, "level_pct": level, "shot": shot, "method": method,
                "success_ratio": success_ratio(sel, case.true_errors), "n_detected": int(sel.size),
                "n_true_detected": int(np.isin(sel, case.true_errors).sum()),
                "selected": " ".join(case.parameter_names[i] for i in sel),
            })
    return rows


def run_study(case, levels, shots: int = 20, methods=("tls-qrf", "svd-qr", "min-norm"), kinds=("qms",),
              seed: int = 0, rank: int | None = None, workers: int | None = None, progress: bool = True,
              batch: int = 5, scheduler=None) -> pd.DataFrame:
    """Localise on ``shots`` noisy data sets per noise level (%) and equation type with every
    method; one DataFrame row per (equations, level_pct, shot, method). Shot noise is seeded
    from (seed, equation type, level, shot), so results do not depend on where the shots ran.
    ``workers``: local processes (default all cores; 1 runs in this process); ``scheduler``: a Dask
    scheduler address to run the batches on a cluster instead (:func:`pcbdyn.parallel.run_jobs`).
    ``rank``: None (automatic), k >= 0 or k < 0 meaning n_params + k, for the rank-based methods."""
    for m in methods:
        if m not in METHODS:
            raise ValueError(f"methods: {m!r} is unknown; choose from {', '.join(METHODS)}")
    for k in kinds:
        if k not in case.kinds:
            raise ValueError(f"equations: {k!r} is unknown for this case; choose from {', '.join(case.kinds)}")
    if shots < 1:
        raise ValueError("shots must be >= 1")
    jobs = [(k, float(lv), list(range(s, min(s + batch, shots))), tuple(methods), seed, rank)
            for k in kinds for lv in levels for s in range(0, shots, batch)]
    total = len(kinds) * len(levels) * shots
    from tqdm import tqdm

    rows = []
    with tqdm(total=total, unit="shot", disable=not progress, desc="localisation study") as bar:
        for _, got in run_jobs(_run_batch, jobs, case, workers, scheduler, done=lambda job: bar.update(len(job[2]))):
            rows += got
    df = pd.DataFrame(rows)
    return df.sort_values(["equations", "method", "level_pct", "shot"], ignore_index=True)


def summarise(df: pd.DataFrame) -> pd.DataFrame:
    """Mean and sample standard deviation of the success ratio (eq. 5.66) per equation type,
    method and noise level, with the number of shots."""
    out = []
    for (kind, method, level), g in df.groupby(["equations", "method", "level_pct"], sort=True):
        mean, std = success_statistics(g["success_ratio"].to_numpy())
        out.append({"equations": kind, "method": method, "level_pct": level, "mean": mean, "std": std,
                    "shots": len(g)})
    return pd.DataFrame(out)
