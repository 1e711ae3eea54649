"""A configuration's K and M with candidate effects added, on one sparsity pattern per set of effects.

Every fit of a diagnosis re-solves the same configurations with other parameter values and effect
magnitudes. The parameters move values only (:class:`pcbdyn.fe.parametric_matrices.ParametricMatrices`
keeps one pattern), and so do the magnitudes: each effect enters K and M linearly through its exact
derivative matrices (:func:`.catalogue.derivatives`). Here the union of the model's pattern and its
effects' is found once per set of effects and kept (:class:`EffectPlan`), so that K and M of every
evaluation share one index: the FE engine's caches keyed by pattern (symbolic factorisation, DOF
groups and the order of their spectra) then hit, and no pattern union is searched per solve.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
import scipy.sparse as sp

from ..fe.sparsity import UnionPattern, canonical_csr, same_array
from .catalogue import BlockCache, derivatives, kind

#: patterns of effect sets kept (least recently used dropped first)
PLANS_KEPT = 64
#: derivatives of the kinds that depend on the parameters kept (least recently used dropped first): many more
#: than a reanalysis asks for (at most 17 on dev seed 2), whose bases and corrections ask for each again
MOVING_KEPT = 4 * PLANS_KEPT


class EffectPlan:
    """The union pattern of a base CSR pattern and the effects' derivative matrices, and where each
    of them sits in it (``base``: positions of the base entries, None where the union is the base's
    own pattern; ``at[k]``: of effect k's). ``own``: the base's pattern alone
    (:meth:`pcbdyn.fe.sparsity.UnionPattern.of`): where the effects lie within it (a mass or a spring
    on a node, a rib along the cells' edges) the union is that pattern, index arrays and all, so
    every later cache keyed by the arrays' identity hits."""

    def __init__(self, base: sp.csr_matrix, parts: list, own: UnionPattern):
        matrices = [A for pair in parts for A in pair]
        inside = all(own.covers(A) for A in matrices)
        self.union = own if inside else UnionPattern(matrices, keep=base)
        self.of = base.indices  # held: the plan is found again by the identity of the base's index
        self.base = None if inside else self.union.positions(base)
        self.at = [(self.union.positions(dK), self.union.positions(dM)) for dK, dM in parts]

    def combine(self, K, M, parts, values) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """K + sum v_k dK_k and M + sum v_k dM_k on the union pattern (shared index arrays)."""
        data = np.zeros((2, self.union.nnz))
        at = slice(None) if self.base is None else self.base
        data[0, at] = K.data
        data[1, at] = M.data
        for (pk, pm), (dK, dM), v in zip(self.at, parts, values):  # positions are unique within each
            data[0, pk] += v * dK.data
            data[1, pm] += v * dM.data
        return self.union.matrix(data[0]), self.union.matrix(data[1])


class Effects:
    """Candidates' derivative matrices per configuration (kept: by name for the kinds that depend on
    the mesh only, by name and parameter values for the others) and the :class:`EffectPlan` of each
    set of effects; ``blocks``: the :class:`.catalogue.BlockCache` the residual's sensitivities share."""

    def __init__(self):
        self.blocks = BlockCache()
        self._fixed: dict = {}
        self._moving: OrderedDict = OrderedDict()
        self._plans: OrderedDict = OrderedDict()
        self._own: dict = {}  # configuration -> the pattern of its K alone

    def derivative(self, k: int, model, cand, p) -> tuple:
        """(dK, dM) of ``cand`` on configuration ``k``'s ``model`` at parameters ``p``, canonical CSR."""
        if getattr(kind(cand.kind), "uses_properties", False):
            key = (k, cand.name, np.asarray(p, float).tobytes())
            if key in self._moving:
                self._moving.move_to_end(key)
            else:
                self._moving[key] = tuple(canonical_csr(A) for A in derivatives(model, cand, self.blocks))
                while len(self._moving) > MOVING_KEPT:
                    self._moving.popitem(last=False)
            return self._moving[key]
        if (k, cand.name) not in self._fixed:
            self._fixed[k, cand.name] = tuple(canonical_csr(A) for A in derivatives(model, cand, self.blocks))
        return self._fixed[k, cand.name]

    def combine(self, k: int, model, K, M, p, candidates, values) -> tuple:
        """(K, M) of configuration ``k`` at ``p`` with the ``candidates`` at ``values`` (those at 0 left out)."""
        on = [(c, float(v)) for c, v in zip(candidates, values) if v != 0.0]
        if not on:
            return K, M
        parts = [self.derivative(k, model, c, p) for c, _ in on]
        key = (k, K.shape, id(K.indices), tuple(c.name for c, _ in on))
        plan = self._plans.get(key)
        if plan is None or plan.of is not K.indices:
            own = self._own.get(k)
            if own is None or not same_array(own.indices, K.indices):
                own = self._own[k] = UnionPattern.of(K)
            plan = self._plans[key] = EffectPlan(K, parts, own)
            while len(self._plans) > PLANS_KEPT:
                self._plans.popitem(last=False)
        else:
            self._plans.move_to_end(key)
        return plan.combine(K, M, parts, [v for _, v in on])

