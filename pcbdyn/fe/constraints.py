"""Constraints by elimination: u_full = T u_red, with fixed DOFs dropped and MPC slaves expressed
through their masters. Reduced matrices are T^T K T and T^T M T.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .model import ModelError


@dataclass
class Reduction:
    """The map from reduced to full DOFs, and which full DOFs are independent unknowns."""

    T: sp.csr_matrix  # (n_full, n_red)
    independent: np.ndarray  # full DOF number of each reduced DOF

    def expand(self, x: np.ndarray) -> np.ndarray:
        """Full vectors (n_full, ...) from reduced ones (n_red, ...)."""
        return self.T @ x

    @property
    def is_selection(self) -> bool:
        """True when T only drops DOFs (one unit entry per column: no MPC terms survive)."""
        return self.T.nnz == self.independent.size

    def reduce(self, A: sp.spmatrix) -> sp.csc_matrix:
        """T^T A T as CSC; by row/column selection when T only drops DOFs (cheaper, exact)."""
        if self.is_selection:
            idx = self.independent
            return sp.csr_matrix(A)[idx][:, idx].tocsc()
        return (self.T.T @ A @ self.T).tocsc()


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
        touched = (abs(K).sum(axis=1).A1 > 0) | (abs(M).sum(axis=1).A1 > 0)
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

    rows = list(independent)
    cols = list(range(independent.size))
    vals = [1.0] * independent.size
    for s in slaves:
        if fixed[s]:
            continue
        for m, c in resolve(s):
            rows.append(s)
            cols.append(col[m])
            vals.append(c)
    T = sp.csr_matrix((vals, (rows, cols)), shape=(n, independent.size))
    return Reduction(T, independent)
