"""Sparse direct solves: one factorisation, many right-hand sides.

Symmetric positive definite matrices (shifted stiffness in shift-invert, static flexibility,
Guyan's K_ss) go to CHOLMOD's supernodal Cholesky (scikit-sparse), which on 6-DOF/node shell
meshes fills about half as much as SuperLU and runs its dense kernels in BLAS. Anything else
(indefinite, complex, or CHOLMOD unavailable) goes to SuperLU with the MMD ordering on A^T + A,
which suits structurally symmetric FE matrices far better than SciPy's default COLAMD.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .model import ModelError

try:
    from sksparse.cholmod import CholmodNotPositiveDefiniteError, cholesky
except ImportError:  # pragma: no cover - scikit-sparse is a declared dependency
    cholesky = None
    CholmodNotPositiveDefiniteError = None


class SingularMatrixError(ModelError):
    """The matrix to factorise is (numerically) singular."""


class Factorization:
    """A factorised square sparse matrix A; ``solve(b)`` returns A^-1 b for b of shape (n,) or (n, k).

    ``method`` is "cholmod" or "superlu". Complex right-hand sides on a real factor are solved as
    two real systems.
    """

    def __init__(self, A, spd: bool = True):
        A = sp.csc_matrix(A)
        if A.shape[0] != A.shape[1]:
            raise ValueError(f"cannot factorise a non-square matrix of shape {A.shape}")
        A.sum_duplicates()
        A.sort_indices()
        self.shape = A.shape
        self.dtype = A.dtype
        self._solve = None
        if spd and cholesky is not None and not np.iscomplexobj(A.data):
            try:
                f = cholesky(A, mode="supernodal")
            except CholmodNotPositiveDefiniteError:
                f = None
            if f is not None:
                self._solve = f
                self.method = "cholmod"
        if self._solve is None:
            try:
                self._solve = spla.splu(A, permc_spec="MMD_AT_PLUS_A").solve
            except RuntimeError as exc:
                raise SingularMatrixError(f"the {A.shape[0]}x{A.shape[0]} matrix is singular ({exc})") from exc
            self.method = "superlu"

    def solve(self, b):
        b = np.asarray(b)
        if b.shape[0] != self.shape[0]:
            raise ValueError(f"right-hand side has {b.shape[0]} rows, the matrix {self.shape[0]}")
        if np.iscomplexobj(b) and not np.iscomplexobj(np.empty(0, self.dtype)):
            return self._real_solve(b.real) + 1j * self._real_solve(b.imag)
        return self._real_solve(b.astype(np.result_type(b.dtype, self.dtype), copy=False))

    def _real_solve(self, b):
        x = self._solve(np.ascontiguousarray(b) if self.method == "superlu" else b)
        return np.asarray(x).reshape(b.shape)

    def __call__(self, b):
        return self.solve(b)

    def operator(self) -> spla.LinearOperator:
        """A^-1 as a LinearOperator (for eigsh's OPinv)."""
        return spla.LinearOperator(self.shape, matvec=self.solve, matmat=self.solve, dtype=self.dtype)


def factorize(A, spd: bool = True) -> Factorization:
    """Factorise sparse ``A``; ``spd=True`` tries Cholesky first (falls back to LU if A is not SPD)."""
    return Factorization(A, spd=spd)
