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


def same_array(a: np.ndarray, b: np.ndarray) -> bool:
    """True when ``a`` and ``b`` are views of the very same memory (SciPy wraps shared index
    arrays in new views, so ``is`` cannot tell): O(1), no comparison of contents."""
    return a.shape == b.shape and a.dtype == b.dtype and a.strides == b.strides and (
        a.__array_interface__["data"][0] == b.__array_interface__["data"][0])


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return same_array(a, b) or (a.shape == b.shape and np.array_equal(a, b))


def row_counts(indptr: np.ndarray, mask: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
    """How many entries of each row ``rows`` (default: all) of a compressed pattern ``indptr`` have
    ``mask`` (one bool per entry) set."""
    starts = indptr[:-1] if rows is None else indptr[rows]
    ends = indptr[1:] if rows is None else indptr[rows + 1]
    padded = np.zeros(mask.size + 1, dtype=bool)  # a False past the end: reduceat may index it
    padded[:-1] = mask
    counts = np.add.reduceat(padded, starts, dtype=np.int32)
    counts[starts == ends] = 0  # reduceat gives an empty row its next entry
    return counts


@dataclass
class Gather:
    """The entries of a source pattern (``indptr``, ``indices``) where ``mask`` is set, forming a
    new compressed matrix (``sub_indptr``, ``sub_indices``) of ``shape`` in format ``fmt`` ("csr"
    or "csc"). A boolean mask streams through the values faster than a gather by positions and
    takes an eighth of their memory."""

    indptr: np.ndarray
    indices: np.ndarray
    mask: np.ndarray
    sub_indptr: np.ndarray
    sub_indices: np.ndarray
    shape: tuple
    fmt: str = "csr"

    @classmethod
    def kept(cls, A, keep: np.ndarray, rows: np.ndarray, cols: np.ndarray, shape, fmt: str = "csr") -> Gather:
        """The plan keeping the entries of CSR ``A`` where ``keep`` (one bool per entry, False in
        every row not in ``rows``) is set, the rows ``rows`` (sorted) of A becoming the new rows and
        ``cols`` (one per entry of A) giving the new column numbers."""
        counts = row_counts(A.indptr, keep, rows)
        sub_indptr = np.zeros(rows.size + 1, dtype=A.indices.dtype)
        np.cumsum(counts, out=sub_indptr[1:])
        return cls(A.indptr, A.indices, keep, sub_indptr, cols[keep], shape, fmt)

    def fits(self, A) -> bool:
        """True when ``A`` has the source pattern of this plan."""
        return _same(A.indptr, self.indptr) and _same(A.indices, self.indices)

    def apply(self, data: np.ndarray):
        """The new matrix from the values ``data`` on the source pattern."""
        return self.matrix(data[self.mask])

    def matrix(self, values: np.ndarray):
        """The new matrix from its own values (``data[mask]``, or sums of such)."""
        make = sp.csr_matrix if self.fmt == "csr" else sp.csc_matrix
        return make((values, self.sub_indices, self.sub_indptr), shape=self.shape, copy=False)


def selection(A: sp.csr_matrix, idx: np.ndarray) -> Gather:
    """The plan of A[idx][:, idx] (``idx`` sorted, CSR ``A`` with sorted indices), as CSR."""
    n, m = A.shape[0], idx.size
    newcol = np.full(n, -1, dtype=A.indices.dtype)
    newcol[idx] = np.arange(m, dtype=A.indices.dtype)
    cols = newcol[A.indices]
    keep = (cols >= 0) & np.repeat(newcol >= 0, np.diff(A.indptr))
    return Gather.kept(A, keep, idx, cols, (m, m))


def _expanded(starts: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner, position): each i repeated ``counts[i]`` times, with the consecutive positions
    ``starts[i]``, ``starts[i] + 1``, ... of its run."""
    owner = np.repeat(np.arange(counts.size), counts)
    first = np.cumsum(counts) - counts
    return owner, np.arange(owner.size) - first[owner] + starts[owner]


@dataclass
class Projection:
    """The plan of T^T A T for every A on one CSR pattern (``indptr``, ``indices``): the reduced
    matrix's values are one sparse product ``P @ A.data`` on a pattern found once (index arrays shared
    by every matrix it makes, so K and M and every later solve of the model come out on one
    pattern). Multi-point constraints make T more than a selection; the triple product of sparse
    matrices, with the union of K's and M's reduced patterns after it, cost a third of a small
    model's eigen-solution (8.7k DOF, 769 MPCs: 37 of 111 ms)."""

    indptr: np.ndarray
    indices: np.ndarray
    P: sp.csr_matrix
    sub_indptr: np.ndarray
    sub_indices: np.ndarray
    shape: tuple

    @classmethod
    def of(cls, A: sp.csr_matrix, T: sp.csr_matrix) -> Projection:
        """The plan of T^T A T for canonical CSR ``A`` (n, n) and CSR ``T`` (n, m)."""
        m = T.shape[1]
        per_row = np.diff(T.indptr)
        rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
        e1, ti = _expanded(T.indptr[rows], per_row[rows])  # entry e = (r, c) meets T's row r ...
        e2, tj = _expanded(T.indptr[A.indices[e1]], per_row[A.indices[e1]])  # ... and T's row c
        ti, entry = ti[e2], e1[e2]
        keys = T.indices[ti].astype(np.int64) * m + T.indices[tj]
        pattern, at = np.unique(keys, return_inverse=True)
        P = sp.csr_matrix((T.data[ti] * T.data[tj], (at.ravel(), entry)), shape=(pattern.size, A.indices.size))
        sub_indptr = np.zeros(m + 1, dtype=A.indices.dtype)
        np.cumsum(np.bincount(pattern // m, minlength=m), out=sub_indptr[1:])
        return cls(A.indptr, A.indices, P, sub_indptr, (pattern % m).astype(A.indices.dtype), (m, m))

    def fits(self, A) -> bool:
        """True when ``A`` has the source pattern of this plan."""
        return _same(A.indptr, self.indptr) and _same(A.indices, self.indices)

    def apply(self, data: np.ndarray) -> sp.csr_matrix:
        """T^T A T from the values ``data`` of A on the source pattern."""
        return sp.csr_matrix((self.P @ data, self.sub_indices, self.sub_indptr), shape=self.shape, copy=False)


def lower_triangle(A: sp.csr_matrix) -> Gather:
    """The plan of the lower triangle of a symmetric CSR ``A`` as CSC: its upper entries row by row
    are the lower ones column by column, so CHOLMOD gets it without a transpose."""
    n = A.shape[0]
    keep = A.indices >= np.repeat(np.arange(n, dtype=A.indices.dtype), np.diff(A.indptr))
    return Gather.kept(A, keep, np.arange(n), A.indices, A.shape, fmt="csc")


def canonical_csr(A) -> sp.csr_matrix:
    """``A`` as CSR with sorted, summed indices (no copy when it already is)."""
    A = A.tocsr()
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


def entry_keys(A) -> np.ndarray:
    """row x n_columns + column of every stored entry of CSR ``A``: sorted when A is canonical."""
    return np.repeat(np.arange(A.shape[0], dtype=np.int64), np.diff(A.indptr)) * A.shape[1] + A.indices


class UnionPattern:
    """The union of the nonzero patterns of CSR ``matrices`` and of every stored entry of ``keep``
    (its explicit zeros too), and where a matrix's entries sit in it: found once per matrix
    (:meth:`positions`), after which its values are placed by one scatter."""

    def __init__(self, matrices, keep=None):
        union = None if keep is None else sp.csr_matrix((np.ones(keep.nnz), keep.indices, keep.indptr), shape=keep.shape)
        for A in matrices:
            union = abs(A) if union is None else union + abs(A)
        union = canonical_csr(union)
        self.indptr, self.indices, self.shape = union.indptr, union.indices, union.shape
        self._keys = entry_keys(union)

    @classmethod
    def of(cls, A) -> UnionPattern:
        """The pattern of canonical CSR ``A`` alone, on A's own index arrays (every matrix it makes
        shares them)."""
        out = cls.__new__(cls)
        out.indptr, out.indices, out.shape, out._keys = A.indptr, A.indices, A.shape, entry_keys(A)
        return out

    def covers(self, A) -> bool:
        """True when every stored entry of canonical CSR ``A`` has its place in this pattern."""
        keys = entry_keys(A)
        at = np.searchsorted(self._keys, keys)
        return bool(np.all(at < self._keys.size) and np.array_equal(self._keys[np.minimum(at, self._keys.size - 1)], keys))

    @property
    def nnz(self) -> int:
        return self.indices.size

    def positions(self, A) -> np.ndarray:
        """Where each stored entry of canonical CSR ``A`` sits in the union (an entry the union lacks,
        an explicit zero of A, gets a meaningless position: place only nonzero values)."""
        return np.searchsorted(self._keys, entry_keys(A))

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with values ``data`` on the union (index arrays shared, not copied)."""
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape, copy=False)


def common_pattern(K, M) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """K and M as canonical CSR on one pattern, index arrays shared. Assembled and reduced pairs
    already share theirs; otherwise the union of their nonzeros is taken (an entry zero in both
    is dropped)."""
    K, M = canonical_csr(K), canonical_csr(M)
    if same_array(K.indices, M.indices) and same_array(K.indptr, M.indptr):
        return K, M
    if _same(K.indptr, M.indptr) and _same(K.indices, M.indices):
        return K, sp.csr_matrix((M.data, K.indices, K.indptr), shape=M.shape, copy=False)
    union = UnionPattern([K, M])

    def place(A):
        data = np.zeros(union.nnz)
        nz = A.data != 0
        data[union.positions(A)[nz]] = A.data[nz]
        return union.matrix(data)

    return place(K), place(M)
