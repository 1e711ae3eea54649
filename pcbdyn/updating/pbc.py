"""Perturbed-boundary-condition (PBC) stacking of several configurations' equations (thesis ch. 6).

Configurations share the parameters (the columns); their weighted blocks are stacked (eq. 6.4),
optionally after an SVD reduction of each block to n rows (eqs. 6.5-6.6), which keeps the
least-squares problem and drops only the residues that no parameter change can remove.
"""

from __future__ import annotations

import numpy as np

from .equations import Block


def svd_reduce(A, b) -> Block:
    """Sigma V^T x = U^T b with the thin SVD A = U Sigma V^T (thesis eqs. 6.5-6.6)."""
    U, s, Vt = np.linalg.svd(np.asarray(A, float), full_matrices=False)
    return Block(s[:, None] * Vt, U.T @ np.asarray(b, float))


def stack(blocks, reduce: bool = False) -> Block:
    """Stack the (A_c, b_c) of all configurations (eq. 6.4); with ``reduce`` each block is first
    SVD-reduced (eq. 6.6), which gives the same least-squares normal equations with fewer rows."""
    blocks = [Block(np.asarray(A, float), np.asarray(b, float)) for A, b in blocks]
    if not blocks:
        raise ValueError("blocks: give at least one configuration's (A, b)")
    n = {blk.A.shape[1] for blk in blocks}
    if len(n) != 1:
        raise ValueError(f"blocks have {sorted(n)} columns: every configuration must use the same parameters")
    if reduce:
        blocks = [svd_reduce(*blk) for blk in blocks]
    return Block(np.vstack([blk.A for blk in blocks]), np.concatenate([blk.b for blk in blocks]))


def condition_number(A) -> float:
    """2-norm condition number sigma_1 / sigma_n (thesis eq. 4.10); inf when A has fewer rows than
    columns or is singular to round-off."""
    A = np.asarray(A, float)
    s = np.linalg.svd(A, compute_uv=False)
    if A.shape[0] < A.shape[1] or s[-1] <= 1e-14 * s[0]:
        return np.inf
    return float(s[0] / s[-1])


def condition_numbers(blocks) -> dict:
    """Condition number of every configuration's A and of the stacked A (as thesis Table 6.6)."""
    blocks = list(blocks)
    return {
        "per_configuration": [condition_number(A) for A, _ in blocks],
        "stacked": condition_number(stack(blocks).A),
    }
