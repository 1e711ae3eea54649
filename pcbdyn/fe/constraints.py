"""Constraints by elimination: u_full = T u_red, with fixed DOFs dropped and MPC slaves expressed
through their masters. Reduced matrices are T^T K T and T^T M T.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .model import ModelError
from .sparsity import Gather, canonical_csr, row_counts, same_array, selection


@dataclass
class Reduction:
    """The map from reduced to full DOFs, and which full DOFs are independent unknowns."""

    T: sp.csr_matrix  # (n_full, n_red)
    independent: np.ndarray  # full DOF number of each reduced DOF
    _selection: Gather | None = field(default=None, repr=False, compare=False)

    def expand(self, x: np.ndarray) -> np.ndarray:
        """Full vectors (n_full, ...) from reduced ones (n_red, ...)."""
        return self.T @ x

    @property
    def is_selection(self) -> bool:
        """True when T only drops DOFs (one unit entry per column: no MPC terms survive)."""
        return self.T.nnz == self.independent.size

    def reduce(self, A: sp.spmatrix) -> sp.csr_matrix:
        """T^T A T as CSR. When T only drops DOFs, by row/column selection (exact, no products):
        the entries' positions are found once per sparsity pattern and reused, so K and M (which
        share their index arrays) cost one search, and the reduced pair shares its index arrays too.
        """
        if not self.is_selection:
            return (self.T.T @ A @ self.T).tocsr()
        A = canonical_csr(A)
        if self._selection is None or not self._selection.fits(A):
            self._selection = selection(A, self.independent)
        return self._selection.apply(A.data)


def build_reduction(model, K=None, M=None) -> Reduction:
    """Eliminate fixed DOFs, MPC slaves and DOFs no element touches (zero rows in both K and M).

    Chains of MPCs (a master that is itself a slave) are resolved; a slave that depends on itself
    is an error.
    """
    n = model.n_dof
    slaves = {}
    for s, terms in model.mpcs:
        if s in slaves:
            raise ModelError(f"DOF {s} is the slave of two multi-point constraints")
        slaves[int(s)] = [(int(m), float(c)) for m, c in terms]
    fixed = np.zeros(n, dtype=bool)
    if model.fixed:
        fixed[np.fromiter(model.fixed, dtype=np.int64)] = True
    untouched = np.zeros(n, dtype=bool)
    if K is not None and M is not None:
        touched = np.zeros(n, dtype=bool)
        K, M = K.tocsr(), M.tocsr()
        if same_array(K.indptr, M.indptr) and same_array(K.indices, M.indices):  # an assembled pair
            held = [(K.indptr, (K.data != 0) | (M.data != 0))]
        else:
            held = [(A.indptr, A.data != 0) for A in (K, M)]
        for indptr, nonzero in held:  # symmetric: a DOF with a nonzero in its column has one in its row
            touched |= row_counts(indptr, nonzero) > 0
        for s, terms in slaves.items():  # a slave's stiffness reaches its masters
            if touched[s]:
                for m, _ in terms:
                    touched[m] = True
        untouched = ~touched
    is_slave = np.zeros(n, dtype=bool)
    if slaves:
        is_slave[np.fromiter(slaves, dtype=np.int64)] = True
    independent = np.flatnonzero(~fixed & ~is_slave & ~untouched)
    col = -np.ones(n, dtype=np.int64)
    col[independent] = np.arange(independent.size)

    def resolve(dof, depth=0):
        if depth > 50:
            raise ModelError(f"multi-point constraints form a cycle through DOF {dof}")
        if dof in slaves:
            out = []
            for m, c in slaves[dof]:
                out.extend((mm, c * cc) for mm, cc in resolve(m, depth + 1))
            return out
        if fixed[dof] or col[dof] < 0:
            return []
        return [(dof, 1.0)]

    terms = [(s, col[m], c) for s in slaves if not fixed[s] for m, c in resolve(s)]
    rows, cols, vals = (np.array(v) for v in zip(*terms)) if terms else (np.zeros(0, dtype=np.int64),) * 3
    rows = np.concatenate([independent, rows]).astype(np.int64)
    cols = np.concatenate([np.arange(independent.size), cols]).astype(np.int64)
    vals = np.concatenate([np.ones(independent.size), vals]).astype(float)
    T = sp.csr_matrix((vals, (rows, cols)), shape=(n, independent.size))
    return Reduction(T, independent)
