"""Index plans on CSR patterns: which entries of a matrix make a submatrix or its lower triangle.

A plan is found once per sparsity pattern and then turns any value array on that pattern into
the new matrix by one gather, so K and M (which share their pattern) and every later solve of
the same model (other parameter values) pay the index search once. Nothing here is a COO or a
fancy-indexing copy of the whole matrix.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and np.array_equal(a, b))


@dataclass
class Gather:
    """Entries ``positions`` of a source pattern (``indptr``, ``indices``) forming a new compressed
    matrix (``sub_indptr``, ``sub_indices``) of ``shape``, in format ``fmt`` ("csr" or "csc")."""

    indptr: np.ndarray
    indices: np.ndarray
    positions: np.ndarray
    sub_indptr: np.ndarray
    sub_indices: np.ndarray
    shape: tuple
    fmt: str = "csr"

    @classmethod
    def kept(cls, A, keep: np.ndarray, rows: np.ndarray, cols: np.ndarray, shape, fmt: str = "csr") -> "Gather":
        """The plan keeping the entries of CSR ``A`` where ``keep`` (one bool per entry, plus one
        False past the end) is set, in rows ``rows`` (sorted) of A, their new column numbers
        being ``cols`` (one per entry of A)."""
        lengths = np.diff(A.indptr)
        counts = np.add.reduceat(keep, A.indptr[:-1], dtype=np.int64)
        counts[lengths == 0] = 0  # reduceat gives an empty row its next entry
        sub_indptr = np.zeros(rows.size + 1, dtype=A.indices.dtype)
        np.cumsum(counts[rows], out=sub_indptr[1:])
        positions = np.flatnonzero(keep)
        return cls(A.indptr, A.indices, positions, sub_indptr, cols[positions], shape, fmt)

    def fits(self, A) -> bool:
        """True when ``A`` has the source pattern of this plan."""
        return _same(A.indptr, self.indptr) and _same(A.indices, self.indices)

    def apply(self, data: np.ndarray):
        """The new matrix from the values ``data`` on the source pattern."""
        return self.matrix(data[self.positions])

    def matrix(self, values: np.ndarray):
        """The new matrix from its own values (``data[positions]``, or sums of such)."""
        make = sp.csr_matrix if self.fmt == "csr" else sp.csc_matrix
        return make((values, self.sub_indices, self.sub_indptr), shape=self.shape, copy=False)


def selection(A: sp.csr_matrix, idx: np.ndarray) -> Gather:
    """The plan of A[idx][:, idx] (``idx`` sorted, CSR ``A`` with sorted indices), as CSR."""
    n, m = A.shape[0], idx.size
    newcol = np.full(n, -1, dtype=A.indices.dtype)
    newcol[idx] = np.arange(m, dtype=A.indices.dtype)
    cols = newcol[A.indices]
    keep = np.zeros(cols.size + 1, dtype=bool)  # one False past the end for reduceat
    np.logical_and(cols >= 0, np.repeat(newcol >= 0, np.diff(A.indptr)), out=keep[:-1])
    return Gather.kept(A, keep, idx, cols, (m, m))


def lower_triangle(A: sp.csr_matrix) -> Gather:
    """The plan of the lower triangle of a symmetric CSR ``A`` as CSC: its upper entries row by row
    are the lower ones column by column, so CHOLMOD gets it without a transpose."""
    n = A.shape[0]
    rows = np.repeat(np.arange(n, dtype=A.indices.dtype), np.diff(A.indptr))
    keep = np.zeros(A.indices.size + 1, dtype=bool)
    np.greater_equal(A.indices, rows, out=keep[:-1])
    return Gather.kept(A, keep, np.arange(n), A.indices, A.shape, fmt="csc")


def canonical_csr(A) -> sp.csr_matrix:
    """``A`` as CSR with sorted, summed indices (no copy when it already is)."""
    A = A.tocsr()
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


def common_pattern(K, M) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """K and M as canonical CSR on one pattern, index arrays shared. Assembled and reduced pairs
    already share theirs; otherwise the union of their nonzeros is taken (an entry zero in both
    is dropped)."""
    K, M = canonical_csr(K), canonical_csr(M)
    if K.indices is M.indices and K.indptr is M.indptr:
        return K, M
    if _same(K.indptr, M.indptr) and _same(K.indices, M.indices):
        return K, sp.csr_matrix((M.data, K.indices, K.indptr), shape=M.shape, copy=False)
    union = canonical_csr(abs(K) + abs(M))
    n = K.shape[0]

    def keys(A):
        return np.repeat(np.arange(n, dtype=np.int64), np.diff(A.indptr)) * n + A.indices

    where = keys(union)

    def place(A):
        data = np.zeros(union.nnz)
        nz = A.data != 0
        data[np.searchsorted(where, keys(A)[nz])] = A.data[nz]
        return sp.csr_matrix((data, union.indices, union.indptr), shape=A.shape, copy=False)

    return place(K), place(M)
