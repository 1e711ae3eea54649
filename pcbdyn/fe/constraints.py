"""Constraints by elimination: u_full = T u_red, with fixed DOFs dropped and MPC slaves expressed
through their masters. Reduced matrices are T^T K T and T^T M T.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .linsolve import pattern_key
from .model import ModelError
from .sparsity import Gather, Projection, canonical_csr, row_counts, same_array, selection


#: reduction plans kept across :class:`Reduction` objects (each solve of a model builds its own, on the
#: same T), found by T's digest and the pattern of the matrix reduced; as many as the FE engine's
#: other caches keyed by pattern (:data:`.blocks.LAYOUT_CACHE_SIZE`)
PLANS_KEPT = 8
_plans: OrderedDict = OrderedDict()
_resolved: OrderedDict = OrderedDict()  # the MPC chains followed (:func:`_chains`), as many


@dataclass
class Reduction:
    """The map from reduced to full DOFs, and which full DOFs are independent unknowns."""

    T: sp.csr_matrix  # (n_full, n_red)
    independent: np.ndarray  # full DOF number of each reduced DOF
    _plan: Gather | Projection | None = field(default=None, repr=False, compare=False)
    _digest: bytes | None = field(default=None, repr=False, compare=False)

    def expand(self, x: np.ndarray) -> np.ndarray:
        """Full vectors (n_full, ...) from reduced ones (n_red, ...)."""
        return self.T @ x

    @property
    def is_selection(self) -> bool:
        """True when T only drops DOFs (one unit entry per column: no MPC terms survive)."""
        return self.T.nnz == self.independent.size

    def reduce(self, A: sp.spmatrix) -> sp.csr_matrix:
        """T^T A T as CSR, by a plan found once per T and sparsity pattern and reused (by later
        reductions with the same T too): a row/column selection when T only drops DOFs, else a
        projection of A's values (:class:`.sparsity.Projection`). K and M, which share their index
        arrays, cost one search, and every reduced matrix of a pattern shares the plan's index arrays."""
        A = canonical_csr(A)
        if self._plan is None or not self._plan.fits(A):
            self._plan = self._kept_plan(A)
        return self._plan.apply(A.data)

    def _kept_plan(self, A: sp.csr_matrix) -> Gather | Projection:
        if self._digest is None:
            self._digest = pattern_key(np.asarray(self.T.shape), self.T.indptr, self.T.indices, self.T.data)
        key = (self._digest, A.shape, A.indices.size)
        plan = _plans.get(key)
        if plan is None or not plan.fits(A):
            plan = selection(A, self.independent) if self.is_selection else Projection.of(A, self.T)
            _plans[key] = plan
            while len(_plans) > PLANS_KEPT:
                _plans.popitem(last=False)
        _plans.move_to_end(key)
        return plan


def _chains(mpcs) -> tuple[np.ndarray, tuple, tuple]:
    """(the slave DOFs, (master, slave) of every constraint term, (slave, master, coefficient) with
    every chain of MPCs (a master that is itself a slave) followed to DOFs that are no slave), kept
    by the constraints' digest: every solve of a model reduces it anew, and following 800 chains in
    Python took 5 ms of a small model's 80 ms solve."""
    flat = [(int(s), int(m), float(c)) for s, terms in mpcs for m, c in terms]
    sizes = np.array([len(terms) for _, terms in mpcs], dtype=np.int64)
    key = pattern_key(sizes, np.array(flat, dtype=float).reshape(-1, 3))
    if key in _resolved:
        _resolved.move_to_end(key)
        return _resolved[key]
    slaves = {}
    for s, terms in mpcs:
        if s in slaves:
            raise ModelError(f"DOF {s} is the slave of two multi-point constraints")
        slaves[int(s)] = [(int(m), float(c)) for m, c in terms]

    def resolve(dof, depth=0):
        if depth > 50:
            raise ModelError(f"multi-point constraints form a cycle through DOF {dof}")
        if dof not in slaves:
            return [(dof, 1.0)]
        return [(mm, c * cc) for m, c in slaves[dof] for mm, cc in resolve(m, depth + 1)]

    leaves = [(s, m, c) for s in slaves for m, c in resolve(s)]
    arrays = (np.array([t[0] for t in leaves], dtype=np.int64), np.array([t[1] for t in leaves], dtype=np.int64),
              np.array([t[2] for t in leaves], dtype=float))
    direct = np.array([t[1] for t in flat], dtype=np.int64), np.array([t[0] for t in flat], dtype=np.int64)
    _resolved[key] = (np.fromiter(slaves, dtype=np.int64, count=len(slaves)), direct, arrays)
    while len(_resolved) > PLANS_KEPT:
        _resolved.popitem(last=False)
    return _resolved[key]


def build_reduction(model, K=None, M=None) -> Reduction:
    """Eliminate fixed DOFs, MPC slaves and DOFs no element touches (zero rows in both K and M).

    Chains of MPCs (a master that is itself a slave) are resolved; a slave that depends on itself
    is an error.
    """
    n = model.n_dof
    slaves, (masters, of_slave), (leaf_slave, leaf_master, leaf_coef) = _chains(model.mpcs)
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
        reached = masters[touched[of_slave]]  # a slave's stiffness reaches its masters (along chains)
        while not touched[reached].all():
            touched[reached] = True
            reached = masters[touched[of_slave]]
        untouched = ~touched
    is_slave = np.zeros(n, dtype=bool)
    is_slave[slaves] = True
    independent = np.flatnonzero(~fixed & ~is_slave & ~untouched)
    col = -np.ones(n, dtype=np.int64)
    col[independent] = np.arange(independent.size)
    kept = ~fixed[leaf_slave] & (col[leaf_master] >= 0)  # a fixed or untouched master adds nothing
    rows, cols, vals = leaf_slave[kept], col[leaf_master[kept]], leaf_coef[kept]
    rows = np.concatenate([independent, rows]).astype(np.int64)
    cols = np.concatenate([np.arange(independent.size), cols]).astype(np.int64)
    vals = np.concatenate([np.ones(independent.size), vals]).astype(float)
    T = sp.csr_matrix((vals, (rows, cols)), shape=(n, independent.size))
    return Reduction(T, independent)
