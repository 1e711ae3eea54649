"""Sparse direct solves: one factorisation, many right-hand sides; one symbolic analysis, many
factorisations.

Symmetric positive definite matrices (shifted stiffness in shift-invert, static flexibility,
Guyan's K_ss) go to CHOLMOD's supernodal Cholesky (scikit-sparse), which on 6-DOF/node shell
meshes fills about half as much as SuperLU and runs its dense kernels in BLAS. Anything else
(indefinite, complex, or CHOLMOD unavailable) goes to SuperLU with the MMD ordering on A^T + A,
which suits structurally symmetric FE matrices far better than SciPy's default COLAMD.

CHOLMOD's symbolic analysis (fill-reducing ordering, elimination tree, supernodes) depends only on
the sparsity pattern. It is kept in a small cache keyed by the pattern, so that a model solved
again with other values (updating, diagnosis, Sturm counts at other shifts) only refactorises
numerically. Large systems are ordered by METIS nested dissection: on shell meshes from ~10^5
DOF it fills far less than AMD (1M-DOF tilted plate: factorisation 22 s against 44 s).
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .model import ModelError
from .sparsity import same_array

try:
    from sksparse.cholmod import CholmodNotPositiveDefiniteError, analyze, cholesky
except ImportError:  # pragma: no cover - scikit-sparse is a declared dependency
    cholesky = analyze = None
    CholmodNotPositiveDefiniteError = None

#: from this order up, CHOLMOD orders by METIS nested dissection instead of AMD. METIS's analysis
#: costs more (118k-DOF shell group: 1.0 s against 0.15 s) but its factor fills less (factorisation
#: 0.65 s against 0.85 s; 1M DOF: 22 s against 44 s).
METIS_MIN = 150_000
#: symbolic analyses kept (least recently used dropped first)
SYMBOLIC_CACHE_SIZE = 8
_symbolic: OrderedDict = OrderedDict()


class SingularMatrixError(ModelError):
    """The matrix to factorise is (numerically) singular."""


def lower_csc(A) -> sp.csc_matrix:
    """The lower triangle of square ``A`` as canonical CSC: all CHOLMOD reads of a symmetric matrix."""
    return _canonical_csc(sp.tril(A, format="csc"))


def pattern_key(*arrays) -> bytes:
    """A digest of index (or mask) arrays: equal patterns give equal keys."""
    h = hashlib.blake2b(digest_size=16)
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype, a.shape)).encode())
        h.update(a.view(np.uint8).ravel())
    return h.digest()


def cholmod_factor(L: sp.csc_matrix, mode: str = "supernodal"):
    """CHOLMOD factor of the symmetric matrix whose lower triangle is ``L`` (canonical CSC), with
    the symbolic analysis taken from the pattern cache when the pattern was seen before (found by
    the identity of its index arrays, as plans reuse them, else by their digest).
    ``mode`` "supernodal" gives L L^T; "simplicial" gives L D L^T. Raises
    CholmodNotPositiveDefiniteError like scikit-sparse's ``cholesky``."""
    key = next((k for k, (p, i, _) in _symbolic.items()
                if k[0] == mode and same_array(p, L.indptr) and same_array(i, L.indices)), None)
    if key is None:  # not the very index arrays of a kept analysis: compare digests
        key = (mode, L.shape, pattern_key(L.indptr, L.indices))
    if key in _symbolic:
        _symbolic.move_to_end(key)
        symbolic = _symbolic[key][2]
    else:
        order = "metis" if L.shape[0] >= METIS_MIN else "amd"
        symbolic = analyze(L, mode=mode, ordering_method=order)
        _symbolic[key] = (L.indptr, L.indices, symbolic)
        while len(_symbolic) > SYMBOLIC_CACHE_SIZE:
            _symbolic.popitem(last=False)
    return symbolic.cholesky(L)


def clear_symbolic_cache() -> None:
    """Forget every kept symbolic analysis (to free its memory)."""
    _symbolic.clear()


class Factorization:
    """A factorised square sparse matrix A; ``solve(b)`` returns A^-1 b for b of shape (n,) or (n, k).

    ``method`` is "cholmod" or "superlu"; ``factor`` is the CHOLMOD factor (scikit-sparse
    ``Factor``: ``P()``, ``L()``, ``logdet()``...) or SciPy's SuperLU object. Complex right-hand
    sides on a real factor are solved as two real systems. ``lower=True`` says that ``A`` holds
    only the lower triangle of a symmetric matrix (CSC), as CHOLMOD wants it: no copy is made.
    """

    def __init__(self, A, spd: bool = True, lower: bool = False):
        if A.shape[0] != A.shape[1]:
            raise ValueError(f"cannot factorise a non-square matrix of shape {A.shape}")
        self.shape = A.shape
        self.dtype = A.dtype
        self.factor = None
        if spd and cholesky is not None and not np.iscomplexobj(A.data):
            try:
                self.factor = cholmod_factor(_canonical_csc(A) if lower else lower_csc(A))
                self.method = "cholmod"
            except CholmodNotPositiveDefiniteError:
                self.factor = None
        if self.factor is None:
            if lower:
                A = A + sp.tril(A, k=-1).T
            try:
                self.factor = spla.splu(_canonical_csc(A), permc_spec="MMD_AT_PLUS_A")
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
        if self.method == "superlu":
            x = self.factor.solve(np.ascontiguousarray(b))
        else:
            x = self.factor(b)
        return np.asarray(x).reshape(b.shape)

    def __call__(self, b):
        return self.solve(b)

    def forward(self, b):
        """L^-1 P b, where A = P^T L L^T P (CHOLMOD only): half a solve, for symmetric operators."""
        return self.factor.solve_L(self.factor.apply_P(b), use_LDLt_decomposition=False)

    def backward(self, y):
        """P^T L^-T y, the other half: ``backward(forward(b))`` is ``solve(b)``."""
        return self.factor.apply_Pt(self.factor.solve_Lt(y, use_LDLt_decomposition=False))

    def operator(self) -> spla.LinearOperator:
        """A^-1 as a LinearOperator (for eigsh's OPinv)."""
        return spla.LinearOperator(self.shape, matvec=self.solve, matmat=self.solve, dtype=self.dtype)


def negative_eigenvalue_count(A, lower: bool = False) -> int:
    """How many eigenvalues of the symmetric sparse ``A`` are negative (``lower``: A holds only
    its lower triangle, CSC).

    By Sylvester's law of inertia this is the number of negative pivots of A = L D L^T pivoted on
    the diagonal only. Applied to K - s M it counts the eigenvalues of the pencil below s (the Sturm
    sequence property used by shift-invert Lanczos codes to know that no mode was missed). SuperLU
    in symmetric mode (:func:`_superlu_pivots`) gives the pivots first: CHOLMOD's LDL^T is simplicial
    only, and on unstructured meshes SuperLU's supernodal kernels take less time (one group of the
    six-part card at 1.7 mm, 36.6k DOF: 0.9 s against 2.3 s; the ribbed housing at 5 mm, 26k DOF:
    1.0 s against 4.4 s; the same at 3k DOF), though not on a plain square plate's regular grid (15k
    DOF: 0.5 s against 0.4 s). Where SuperLU leaves the diagonal or meets a zero pivot, CHOLMOD's
    simplicial LDL^T gives them.
    """
    L = _canonical_csc(A) if lower else lower_csc(A)
    d = _superlu_pivots(L)
    if d is None and cholesky is not None:
        try:
            d = cholmod_factor(L, mode="simplicial").D()
        except CholmodNotPositiveDefiniteError:
            d = None
    if d is None or not np.all(np.isfinite(d)) or np.any(d == 0):
        raise SingularMatrixError(f"the {A.shape[0]}x{A.shape[0]} matrix is singular, or no symmetric pivot "
                                  "order gives an LDL^T factorisation: the inertia is unknown")
    return int(np.count_nonzero(d < 0))


def _superlu_pivots(L: sp.csc_matrix):
    """The pivots D of P A P^T = L D L^T by SuperLU (a symmetric minimum-degree order, diagonal
    pivots only, so U = D L^T) of the symmetric matrix whose lower triangle is ``L``; None where it
    meets a zero pivot or takes one off the diagonal."""
    full = _canonical_csc(L + sp.tril(L, k=-1).T)
    try:
        lu = spla.splu(full, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    except RuntimeError:
        return None
    d = lu.U.diagonal()
    ok = np.array_equal(lu.perm_r, lu.perm_c) and np.all(np.isfinite(d)) and np.all(d != 0)
    return d if ok else None


def has_no_negative_eigenvalue(A, lower: bool = False) -> bool:
    """True when the symmetric sparse ``A`` is positive (semi)definite: a supernodal Cholesky
    succeeds, about three times faster than the LDL^T of :func:`negative_eigenvalue_count`."""
    if cholesky is None:
        return negative_eigenvalue_count(A, lower) == 0
    try:
        cholmod_factor(_canonical_csc(A) if lower else lower_csc(A))
    except CholmodNotPositiveDefiniteError:
        return False
    return True


def _canonical_csc(A) -> sp.csc_matrix:
    A = sp.csc_matrix(A)
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


def factorize(A, spd: bool = True, lower: bool = False) -> Factorization:
    """Factorise sparse ``A``; ``spd=True`` tries Cholesky first (falls back to LU if A is not SPD).
    ``lower=True``: A is the lower triangle (CSC) of a symmetric matrix."""
    return Factorization(A, spd=spd, lower=lower)
