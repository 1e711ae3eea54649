"""Vectorised sparse assembly of global K and M, for the whole model or a subset of element sets.

Every element couples all six DOFs of each of its nodes, so the global sparsity pattern is made
of dense 6 x 6 node blocks. The pattern is built once per call from node pairs (36 times fewer
keys than DOF triplets) and the element matrices of K and M are both summed into it, in chunks
of cells, so that neither DOF-level triplet lists nor a second COO->CSR conversion are needed.

Subset assembly is what makes parameter sensitivities cheap: dK/dp of a parameter that
touches one set needs only that set's element matrices.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .elements import kernel
from .mesh import NDOF

#: element matrices are computed and summed this many cells at a time (bounds the peak memory)
CHUNK_CELLS = 4096


def element_matrices(model, name: str, prop=None):
    """Element K and M of set ``name`` (optionally with another property), shape (n_cells, nd, nd)."""
    es = model.sets[name]
    return kernel(es.etype)(model.nodes[es.conn], es.prop if prop is None else prop)


def _node_pairs(conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row node, column node) of every node block of every cell, cell-major, each (n_cells * npc^2,)."""
    conn = np.asarray(conn, dtype=np.int64)
    npc = conn.shape[1]
    return np.repeat(conn, npc, axis=1).ravel(), np.tile(conn, (1, npc)).ravel()


def _node_blocks(Ae: np.ndarray) -> np.ndarray:
    """Element matrices (n_cells, 6 npc, 6 npc) as 6 x 6 node blocks (n_cells * npc^2, 6, 6),
    in the order of :func:`_node_pairs`."""
    nc, nd, _ = Ae.shape
    npc = nd // NDOF
    return Ae.reshape(nc, npc, NDOF, npc, NDOF).transpose(0, 1, 3, 2, 4).reshape(nc * npc * npc, NDOF, NDOF)


class _Pattern:
    """The node-block sparsity pattern of a set of cells: sorted unique (row, col) node pairs and,
    for each pair of each cell, its block number."""

    def __init__(self, n_nodes: int, conns: list[np.ndarray]):
        keys = [r * n_nodes + c for r, c in map(_node_pairs, conns)]
        allkeys = np.concatenate(keys) if keys else np.zeros(0, dtype=np.int64)
        self.keys, inverse = np.unique(allkeys, return_inverse=True)
        self.n_nodes = n_nodes
        bounds = np.cumsum([0] + [k.size for k in keys])
        self.slot = [inverse[a:b].astype(np.int64, copy=False) for a, b in zip(bounds[:-1], bounds[1:])]

    def empty(self) -> np.ndarray:
        return np.zeros((self.keys.size, NDOF, NDOF))

    def to_csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The global DOF matrix (CSR, sorted indices) from summed node blocks ``data``."""
        nn = self.n_nodes
        rows, cols = np.divmod(self.keys, nn)
        indptr = np.zeros(nn + 1, dtype=np.int64)
        np.cumsum(np.bincount(rows, minlength=nn), out=indptr[1:])
        idx = np.int32 if max(self.keys.size, NDOF * nn) < np.iinfo(np.int32).max else np.int64  # CSR widens if needed
        A = sp.bsr_matrix((data, cols.astype(idx), indptr.astype(idx)), shape=(NDOF * nn, NDOF * nn))
        return A.tocsr()


def _accumulate(data: np.ndarray, slot: np.ndarray, blocks: np.ndarray) -> None:
    """data[slot[i]] += blocks[i] for every i, duplicates included: one sort of the slots, then
    the sums of each run as a 0/1 sparse matrix times the blocks (36 values per row)."""
    order = np.argsort(slot, kind="stable")
    s = slot[order]
    starts = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])
    indptr = np.r_[starts, s.size]
    S = sp.csr_matrix((np.ones(s.size), order, indptr), shape=(starts.size, s.size))
    data[s[starts]] += (S @ blocks.reshape(s.size, NDOF * NDOF)).reshape(-1, NDOF, NDOF)


def scatter(n_dof: int, conn: np.ndarray, Ae: np.ndarray) -> sp.csr_matrix:
    """Sum element matrices ``Ae`` (n_cells, nd, nd) of cells ``conn`` into an n_dof x n_dof CSR matrix."""
    conn = np.asarray(conn, dtype=np.int64)
    pattern = _Pattern(n_dof // NDOF, [conn])
    data = pattern.empty()
    if conn.size:
        _accumulate(data, pattern.slot[0], _node_blocks(np.asarray(Ae)))
    return pattern.to_csr(data)


def assemble(model, sets=None, props=None):
    """Global (K, M) as CSR matrices over all 6 * n_nodes DOFs, before constraints.

    ``sets``: names of the element sets to include (default: all). ``props``: optional
    {set name: property} overrides, used to evaluate a perturbed set without copying the model.
    Both matrices share one node-block pattern (explicit zeros kept: every element couples all
    six DOFs of its nodes). Element matrices are computed ``CHUNK_CELLS`` cells at a time, and
    the node blocks of small sets are pooled before they are summed in.
    """
    names = list(model.sets) if sets is None else list(sets)
    props = props or {}
    names = [nm for nm in names if len(model.sets[nm].conn) > 0]
    pattern = _Pattern(model.n_dof // NDOF, [model.sets[nm].conn for nm in names])
    K, M = pattern.empty(), pattern.empty()
    pending, size = [], 0

    def flush():
        slot = np.concatenate([p[0] for p in pending])
        _accumulate(K, slot, np.concatenate([p[1] for p in pending]))
        _accumulate(M, slot, np.concatenate([p[2] for p in pending]))
        pending.clear()

    for name, slot in zip(names, pattern.slot):
        es = model.sets[name]
        prop = es.prop if props.get(name) is None else props[name]
        conn = np.asarray(es.conn)
        npp = conn.shape[1] ** 2
        for a in range(0, conn.shape[0], CHUNK_CELLS):
            b = min(a + CHUNK_CELLS, conn.shape[0])
            part = prop.cells(a, b) if hasattr(prop, "cells") else prop  # per-cell data (EmbeddedBeamProperty)
            Ke, Me = kernel(es.etype)(model.nodes[conn[a:b]], part)
            pending.append((slot[a * npp:b * npp], _node_blocks(Ke), _node_blocks(Me)))
            size += (b - a) * npp
            if size >= CHUNK_CELLS * 16:
                flush()
                size = 0
    if pending:
        flush()
    return pattern.to_csr(K), pattern.to_csr(M)
