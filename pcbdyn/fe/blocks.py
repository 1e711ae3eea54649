"""The uncoupled DOF groups of a constrained pencil (K, M), each solved apart, and what is kept
between solves of one sparsity pattern.

A flat plate in a coordinate plane splits exactly into its bending (uz, rx, ry) and membrane
(ux, uy, rz) DOFs; solving the two halves apart needs about a quarter of the factor fill each.
The groups are solved one by one, the one whose spectrum starts lowest first; after it, a group is
asked for exactly its modes below the highest eigenvalue still wanted (a Sturm count), so the
order only decides how much work is done, never which modes are found.

Updating and diagnosis solve one model hundreds of times with other values on the same pattern.
A :class:`Layout`, cached by the nonzero pattern of K and M, keeps what does not change: the groups
(connected components), where each group's entries and their lower triangle sit (gather plans),
and the order in which the groups' spectra started in the last solve (its exact lowest elastic
eigenvalue per group, or a proven lower bound); CHOLMOD's symbolic analysis is kept by
:mod:`.linsolve`. Only the first solve of a pattern estimates the order by block inverse iteration,
and not even that when the caller tells which group is the bending one (``solve_modes`` does, from
the DOFs' directions).
"""

from __future__ import annotations

import functools
import itertools
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .linsolve import pattern_key
from .sparsity import Gather, common_pattern, lower_triangle, same_array, selection

#: reduced systems up to this size are solved densely (all eigenpairs at once)
DENSE_MAX = 600
#: layouts kept (least recently used dropped first)
LAYOUT_CACHE_SIZE = 8
_layouts: OrderedDict = OrderedDict()
_keys = itertools.count()


def _components(K: sp.csr_matrix, nonzero: np.ndarray) -> list[np.ndarray]:
    """Index sets of the DOF groups coupled by the ``nonzero`` entries of K's pattern, largest
    first; groups of at most ``DENSE_MAX`` DOFs are lumped into one last group."""
    n = K.shape[0]
    plan = Gather.kept(K, nonzero, np.arange(n), K.indices, K.shape)
    graph = plan.matrix(np.ones(plan.sub_indices.size))
    # the graph is symmetric, so its strongly connected components are the connected ones, and
    # SciPy finds those without the transposed copy its undirected search makes (2x faster)
    n_comp, label = connected_components(graph, directed=True, connection="strong")
    if n_comp == 1:
        return [np.arange(n)]
    sizes = np.bincount(label)
    big = np.flatnonzero(sizes > DENSE_MAX)
    big = big[np.argsort(-sizes[big], kind="stable")]
    groups = [np.flatnonzero(label == c) for c in big]
    small = np.flatnonzero(sizes[label] <= DENSE_MAX)
    if small.size:
        groups.append(small)
    return groups


class Layout:
    """What one nonzero pattern of (K, M) fixes: the DOF groups, the gather plans of each group's
    matrices and lower triangle (made when first needed), and ``start``: per group, the lowest
    elastic eigenvalue the last solve found there, or a lower bound of it (``nan``: never solved),
    which orders the groups of the next solve."""

    def __init__(self, K: sp.csr_matrix, nonzero: np.ndarray):
        self.groups = _components(K, nonzero)
        self.start = np.full(len(self.groups), np.nan)
        self._select = [None] * len(self.groups)
        self._lower = [None] * len(self.groups)
        self._pattern = (K.shape, K.indptr, K.indices, nonzero)
        self._digest = None

    def digest(self) -> bytes:
        """The digest of the pattern this layout was made for (computed when first compared)."""
        if self._digest is None:
            self._digest = _digest(*self._pattern)
        return self._digest

    def fits(self, K: sp.csr_matrix, nonzero: np.ndarray, digest) -> bool:
        """True when the layout was made for the pattern of K and ``nonzero``: the very index
        arrays and an equal mask, or an equal digest (``digest()`` gives the pencil's, computed at
        most once by the caller)."""
        shape, indptr, indices, mask = self._pattern
        if shape != K.shape or indices.size != K.indices.size:
            return False
        if same_array(indptr, K.indptr) and same_array(indices, K.indices):
            return np.array_equal(mask, nonzero)
        return self.digest() == digest()

    def block(self, g: int, K: sp.csr_matrix, M: sp.csr_matrix) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Group ``g``'s blocks of K and M (K, M themselves when there is one group)."""
        if len(self.groups) == 1:
            return K, M
        if self._select[g] is None:
            self._select[g] = selection(K, self.groups[g])
        return self._select[g].apply(K.data), self._select[g].apply(M.data)

    def lower(self, g: int, Kb: sp.csr_matrix):
        """The gather plan of the lower triangle (CSC) of group ``g``'s block ``Kb``."""
        if self._lower[g] is None:
            self._lower[g] = lower_triangle(Kb)
        return self._lower[g]


def _digest(shape, indptr, indices, nonzero) -> bytes:
    return pattern_key(np.asarray(shape), indptr, indices, nonzero)


def layout(K, M) -> tuple[Layout, sp.csr_matrix, sp.csr_matrix]:
    """The (cached) layout of the pencil and K, M as CSR on one shared pattern. A cached layout is
    found by the identity of the index arrays (reduced matrices share their plan's), else by a
    digest of the pattern, computed only when a kept layout has the same size (at 112k DOF the
    digest costs 30 ms, a first solve's 2 %)."""
    K, M = common_pattern(K, M)
    nonzero = (K.data != 0) | (M.data != 0)
    digest = functools.cache(lambda: _digest(K.shape, K.indptr, K.indices, nonzero))
    key = next((k for k in reversed(_layouts) if _layouts[k].fits(K, nonzero, digest)), None)
    if key is not None:
        _layouts.move_to_end(key)
        return _layouts[key], K, M
    lay = _layouts[next(_keys)] = Layout(K, nonzero)
    while len(_layouts) > LAYOUT_CACHE_SIZE:
        _layouts.popitem(last=False)
    return lay, K, M


def uncoupled_blocks(Kr, Mr) -> list[np.ndarray]:
    """Index sets of the DOF groups that K and M do not couple (exact zeros only), largest first.
    Groups of at most ``DENSE_MAX`` DOFs are lumped into one last block."""
    return layout(Kr, Mr)[0].groups


class ShiftedInverse:
    """(K - S)^-1 on the constrained DOFs, as the eigen-solution factorised it: one CHOLMOD
    factorisation per uncoupled DOF group b of K_b - sigma_b M_b, so S = blockdiag(sigma_b M_b).

    sigma_b = -1e-9 x the group's median K/M diagonal ratio keeps a free model's matrix definite
    and stays far below its first elastic eigenvalue lambda_1: (K - S)^-1 differs from K^-1 by
    about |sigma_b| / lambda_1 (1e-9 on coarse meshes, up to ~1e-4 on very fine shell meshes,
    whose stiffest DOFs raise the median). :meth:`static` removes that by iterative refinement, so
    static flexibility, modal acceleration or FRF residuals of a constrained model need no
    factorisation of their own; for a free model, clear a load of its rigid-body part first
    (inertia relief) and use :meth:`solve`. ``groups`` lists (DOF indices, sigma_b,
    :class:`~.linsolve.Factorization`) per group.
    """

    def __init__(self, n: int, groups: list):
        self.shape = (n, n)
        self.groups = groups

    def solve(self, b):
        b = np.asarray(b)
        x = np.zeros(b.shape, dtype=np.result_type(b.dtype, float))
        for idx, _, f in self.groups:
            x[idx] = f.solve(b[idx])
        return x

    def static(self, K, b, steps: int = 3):
        """K^-1 b for a constrained model (K the reduced stiffness, positive definite): each
        refinement step multiplies the error by about |sigma_b| / lambda_1."""
        x = self.solve(b)
        for _ in range(steps):
            x = x + self.solve(b - K @ x)
        return x
