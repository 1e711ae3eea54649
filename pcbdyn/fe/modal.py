"""Real normal modes of undamped models: K phi = omega^2 M phi, mass-normalised (phi^T M phi = 1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .assembly import assemble
from .constraints import Reduction, build_reduction
from .model import ModelError


@dataclass
class Modes:
    """Elastic modes (frequencies in Hz, full-length mass-normalised shapes as columns) and the
    rigid-body modes found in a free model."""

    frequencies: np.ndarray
    shapes: np.ndarray
    rigid_shapes: np.ndarray
    reduction: Reduction

    @property
    def n_rigid(self) -> int:
        return self.rigid_shapes.shape[1]

    @property
    def omega2(self) -> np.ndarray:
        return (2.0 * np.pi * self.frequencies) ** 2


def _factor(A: sp.csc_matrix):
    """A solver for A x = b: CHOLMOD when available and A is positive definite, else SuperLU."""
    try:
        from sksparse.cholmod import CholmodNotPositiveDefiniteError, cholesky
    except ImportError:  # pragma: no cover - scikit-sparse is a declared dependency
        cholesky = None
    if cholesky is not None:
        try:
            f = cholesky(A)
            return f
        except CholmodNotPositiveDefiniteError:
            pass
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A")
    except RuntimeError as exc:
        raise ModelError(
            "the shifted stiffness matrix is singular: the model has a mechanism or an unsupported "
            "DOF that carries mass; add supports or mark the model free"
        ) from exc
    return lu.solve


def solve_modes(model, n_modes: int | None = None, f_max: float | None = None, K=None, M=None) -> Modes:
    """The first elastic modes of ``model``: ``n_modes`` of them, or all below ``f_max`` [Hz], or both
    (the smaller set). Rigid-body modes of a free model are counted and returned apart.

    A model not declared free that has a zero-frequency mode raises :class:`ModelError`.
    """
    if n_modes is None and f_max is None:
        n_modes = 10
    if K is None or M is None:
        K, M = assemble(model)
    red = build_reduction(model, K, M)
    Kr, Mr = red.reduce(K), red.reduce(M)
    n = Kr.shape[0]
    dk = Kr.diagonal()
    dm = Mr.diagonal()
    if np.any(dm <= 0) and not np.all(dm >= 0):
        raise ModelError("the mass matrix has negative diagonal terms: check densities and masses")
    scale = np.median(dk[dm > 0] / dm[dm > 0]) if np.any(dm > 0) else 1.0
    sigma = -1e-6 * scale
    Ks = (Kr - sigma * Mr).tocsc()
    solve = _factor(Ks)
    op = spla.LinearOperator((n, n), matvec=lambda x: solve(x), dtype=float)
    want = (n_modes or 20) + 6
    while True:
        k = min(want, n - 1)
        lam, vec = spla.eigsh(Kr, k=k, M=Mr, sigma=sigma, which="LM", OPinv=op)
        order = np.argsort(lam)
        lam, vec = lam[order], vec[:, order]
        rigid = np.abs(lam) < 1e-8 * scale
        if f_max is None or k >= n - 1:
            break
        elastic = lam[~rigid]
        if elastic.size and np.sqrt(max(elastic[-1], 0.0)) / (2 * np.pi) > f_max:
            break
        want *= 2
    if rigid.any() and not model.free:
        raise ModelError(
            f"the model has {int(rigid.sum())} zero-frequency mode(s) but is not declared free: "
            "add supports (fixed DOFs, springs) or mark it free"
        )
    lam_e, vec_e = lam[~rigid], vec[:, ~rigid]
    if np.any(lam_e < 0):
        raise ModelError("negative eigenvalues: the stiffness matrix is not positive semi-definite")
    f = np.sqrt(lam_e) / (2.0 * np.pi)
    keep = np.ones(f.size, dtype=bool)
    if f_max is not None:
        keep &= f <= f_max
    idx = np.flatnonzero(keep)
    if n_modes is not None:
        idx = idx[:n_modes]
    shapes = red.expand(vec_e[:, idx])
    rigid_shapes = red.expand(vec[:, rigid])
    return Modes(f[idx], shapes, rigid_shapes, red)
