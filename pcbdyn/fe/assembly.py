"""Vectorised sparse assembly of global K and M, for the whole model or a subset of element sets.

Every element couples all six DOFs of each of its nodes, so the global sparsity pattern is made
of dense 6 x 6 node blocks. The pattern is built once per call from node pairs (36 times fewer
keys than DOF triplets); element matrices are computed ``CHUNK_CELLS`` cells at a time, their node
blocks summed per pattern slot, and the sums added straight into the CSR value arrays of K and
M, which share one index array. So no DOF-level triplet list, COO copy or format conversion is
ever made: at 1M DOF the peak is the two value arrays, one int32 index array and one chunk.

Subset assembly is what makes parameter sensitivities cheap: dK/dp of a parameter that
touches one set needs only that set's element matrices.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .elements import kernel
from .frames import to_global
from .mesh import NDOF

#: element matrices are computed and summed this many cells at a time: it bounds the peak memory,
#: and the temporaries of 1024 quads (4.7 MB per array of 24 x 24 matrices) stay in cache where
#: 4096 did not (112k-DOF plate: assembly 0.82 -> 0.68 s)
CHUNK_CELLS = 1024
_NN = NDOF * NDOF


def element_matrices(model, name: str, prop=None):
    """Element K and M of set ``name`` (optionally with another property), shape (n_cells, nd, nd)."""
    es = model.sets[name]
    return _kernel(model, es, es.conn, es.prop if prop is None else prop)


def _kernel(model, es, conn, prop):
    """(Ke, Me) of cells ``conn`` of set ``es`` in global DOFs (a set in its own frame is computed in
    its axes and turned, :mod:`.frames`)."""
    if es.frame is None:
        return kernel(es.etype)(model.nodes[conn], prop)
    Ke, Me = kernel(es.etype)(model.nodes[conn] @ es.frame, prop)
    return to_global(Ke, es.frame), to_global(Me, es.frame)


def _chunk_matrices(model, name: str, prop=None):
    """(first cell, end cell, Ke, Me) of set ``name`` (its own property, or ``prop``), ``CHUNK_CELLS``
    cells at a time: what bounds the memory of every assembly."""
    es = model.sets[name]
    prop = es.prop if prop is None else prop
    conn = np.asarray(es.conn)
    for a in range(0, conn.shape[0], CHUNK_CELLS):
        b = min(a + CHUNK_CELLS, conn.shape[0])
        part = prop.cells(a, b) if hasattr(prop, "cells") else prop  # per-cell data (EmbeddedBeamProperty)
        yield (a, b, *_kernel(model, es, conn[a:b], part))


def _node_pairs(conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row node, column node) of every node block of every cell, cell-major, each (n_cells * npc^2,)."""
    conn = np.asarray(conn, dtype=np.int64)
    npc = conn.shape[1]
    return np.repeat(conn, npc, axis=1).ravel(), np.tile(conn, (1, npc)).ravel()


def _node_blocks(Ae: np.ndarray) -> np.ndarray:
    """Element matrices (n_cells, 6 npc, 6 npc) as flattened 6 x 6 node blocks (n_cells * npc^2, 36),
    in the order of :func:`_node_pairs`."""
    nc, nd, _ = Ae.shape
    npc = nd // NDOF
    return Ae.reshape(nc, npc, NDOF, npc, NDOF).transpose(0, 1, 3, 2, 4).reshape(nc * npc * npc, _NN)


class _Pattern:
    """The node-block sparsity pattern of a set of cells and its DOF-level CSR layout.

    ``slot[s]`` gives, for each node pair of each cell of conn ``s``, its block number in the
    sorted unique (row node, column node) pairs. Block k of node row r, at position p in that
    row of L_r blocks, holds CSR values ``base[k] + stride[k] * i + j`` (DOF row 6 r + i,
    DOF column 6 c + j): node row r's 6 DOF rows are contiguous, each 6 L_r values long.
    """

    def __init__(self, n_nodes: int, conns: list[np.ndarray]):
        keys = [r * n_nodes + c for r, c in map(_node_pairs, conns)]
        allkeys = np.concatenate(keys) if keys else np.zeros(0, dtype=np.int64)
        ukeys, inverse = np.unique(allkeys, return_inverse=True)
        del allkeys
        self.n_nodes = n_nodes
        self.nnz = _NN * ukeys.size
        self.idx = np.int32 if max(self.nnz, NDOF * n_nodes) < np.iinfo(np.int32).max else np.int64
        inverse = inverse.astype(self.idx, copy=False)
        bounds = np.cumsum([0] + [k.size for k in keys])
        self.slot = [inverse[a:b] for a, b in zip(bounds[:-1], bounds[1:])]
        rows, self.cols = np.divmod(ukeys, n_nodes)
        counts = np.bincount(rows, minlength=n_nodes)
        first = np.zeros(n_nodes + 1, dtype=np.int64)
        np.cumsum(counts, out=first[1:])
        self.base = _NN * first[rows] + NDOF * (np.arange(ukeys.size) - first[rows])
        self.stride = NDOF * counts[rows]
        self.row_len = counts

    def positions(self, blocks: np.ndarray) -> np.ndarray:
        """CSR value positions (len(blocks), 36) of the 6 x 6 entries of node blocks ``blocks``."""
        i, j = np.divmod(np.arange(_NN), NDOF)
        return self.base[blocks][:, None] + self.stride[blocks][:, None] * i + j

    def csr_index(self) -> tuple[np.ndarray, np.ndarray]:
        """(indptr, indices) of the DOF-level CSR matrix, sorted column indices."""
        indptr = np.zeros(NDOF * self.n_nodes + 1, dtype=self.idx)
        np.cumsum(np.repeat(NDOF * self.row_len, NDOF), out=indptr[1:])
        indices = np.empty(self.nnz, dtype=self.idx)
        cols6 = (NDOF * self.cols)[:, None] + np.arange(NDOF)
        for i in range(NDOF):
            indices[(self.base + self.stride * i)[:, None] + np.arange(NDOF)] = cols6
        return indptr, indices

    def to_csr(self, data: np.ndarray, index=None) -> sp.csr_matrix:
        """The n_dof x n_dof CSR matrix with values ``data``; ``index`` = (indptr, indices) to share."""
        indptr, indices = self.csr_index() if index is None else index
        n = NDOF * self.n_nodes
        return sp.csr_matrix((data, indices, indptr), shape=(n, n), copy=False)


def _summing(pattern: _Pattern, slot: np.ndarray):
    """(CSR value positions, S): the runs of equal pattern slots ``slot`` (one per node block) as a
    0/1 sparse matrix S whose product with the blocks (m, 36) sums each run, and the CSR value
    positions of those sums (one sort of the slots, shared by all blocks summed there)."""
    order = np.argsort(slot, kind="stable")
    s = slot[order]
    starts = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])
    S = sp.csr_matrix((np.ones(s.size), order, np.r_[starts, s.size]), shape=(starts.size, s.size))
    return pattern.positions(s[starts]).ravel(), S


def _accumulate(pattern: _Pattern, targets, slot: np.ndarray, blocks) -> None:
    """Add node blocks ``blocks[t]`` (m, 36) into CSR values ``targets[t]`` at pattern slots ``slot``
    (duplicates summed, :func:`_summing`)."""
    pos, S = _summing(pattern, slot)
    for data, b in zip(targets, blocks):
        data[pos] += (S @ b).ravel()


def scatter(n_dof: int, conn: np.ndarray, Ae: np.ndarray) -> sp.csr_matrix:
    """Sum element matrices ``Ae`` (n_cells, nd, nd) of cells ``conn`` into an n_dof x n_dof CSR matrix."""
    conn = np.asarray(conn, dtype=np.int64)
    pattern = _Pattern(n_dof // NDOF, [conn])
    data = np.zeros(pattern.nnz)
    if conn.size:
        _accumulate(pattern, [data], pattern.slot[0], [_node_blocks(np.asarray(Ae))])
    return pattern.to_csr(data)


def assemble(model, sets=None, props=None):
    """Global (K, M) as CSR matrices over all 6 * n_nodes DOFs, before constraints.

    ``sets``: names of the element sets to include (default: all). ``props``: optional
    {set name: property} overrides, used to evaluate a perturbed set without copying the model.
    Both matrices share one node-block pattern, index arrays included (explicit zeros kept: every
    element couples all six DOFs of its nodes); indices are int32 below 2^31 entries. Element
    matrices are computed ``CHUNK_CELLS`` cells at a time, and the node blocks of small sets are
    pooled before they are summed in.
    """
    names = list(model.sets) if sets is None else list(sets)
    props = props or {}
    names = [nm for nm in names if len(model.sets[nm].conn) > 0]
    pattern = _Pattern(model.n_dof // NDOF, [model.sets[nm].conn for nm in names])
    K, M = np.zeros(pattern.nnz), np.zeros(pattern.nnz)
    pending, size = [], 0

    def flush():
        slot = np.concatenate([p[0] for p in pending])
        _accumulate(pattern, (K, M), slot, [np.concatenate([p[t] for p in pending]) for t in (1, 2)])
        pending.clear()

    for name, slot in zip(names, pattern.slot):
        npp = np.asarray(model.sets[name].conn).shape[1] ** 2
        for a, b, Ke, Me in _chunk_matrices(model, name, props.get(name)):
            pending.append((slot[a * npp:b * npp], _node_blocks(Ke), _node_blocks(Me)))
            size += (b - a) * npp
            if size >= CHUNK_CELLS * 16:
                flush()
                size = 0
    if pending:
        flush()
    index = pattern.csr_index()
    return pattern.to_csr(K, index), pattern.to_csr(M, index)


class SetAssembly:
    """The assembled pattern of ``model`` (all its non-empty element sets) and each set's share of
    it: ``positions(name)`` are the CSR value positions a set touches, ``values(name, prop)`` its
    summed K and M entries there with property ``prop``. Sets then combine by adding their values
    at their positions: a model whose sets change one at a time is re-assembled set by set, on one
    pattern whose index arrays (``index``) stay the same objects."""

    def __init__(self, model):
        self.model = model
        self.names = [nm for nm in model.sets if len(model.sets[nm].conn) > 0]
        self.pattern = _Pattern(model.n_dof // NDOF, [model.sets[nm].conn for nm in self.names])
        self.index = self.pattern.csr_index()
        self._sums = {nm: _summing(self.pattern, slot) for nm, slot in zip(self.names, self.pattern.slot)}

    @property
    def nnz(self) -> int:
        return self.pattern.nnz

    def positions(self, name: str) -> np.ndarray:
        return self._sums[name][0]

    def values(self, name: str, prop=None) -> tuple[np.ndarray, np.ndarray]:
        """(K values, M values) of set ``name`` at its :meth:`positions` (its own property by default),
        summed chunk by chunk as :func:`assemble` does."""
        S = self._sums[name][1]
        npp = np.asarray(self.model.sets[name].conn).shape[1] ** 2
        K = M = None
        for a, b, Ke, Me in _chunk_matrices(self.model, name, prop):
            part = S if (b - a) * npp == S.shape[1] else S[:, a * npp:b * npp]
            dK, dM = part @ _node_blocks(Ke), part @ _node_blocks(Me)
            K, M = (dK, dM) if K is None else (K + dK, M + dM)
        return K.ravel(), M.ravel()

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with values ``data`` (length :attr:`nnz`) on the pattern (shared index)."""
        return self.pattern.to_csr(data, self.index)
