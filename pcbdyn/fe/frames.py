"""Parts of a model described in their own frame: a sub-model built in local axes (a plate meshed in
its x-y plane, its constraints written on local DOFs) placed into a global model by a rotation R
(columns: the local axes in global ones) and an origin.

Element sets keep their properties and are computed on the nodes in local axes (their ``frame``), then
turned to global DOFs: K_g = T K_l T^T with T = diag(R, R, ...) over the nodes' 3-vectors of
translations and rotations (:func:`to_global`). Fixed DOFs and multi-point constraints written on local
DOFs are re-expressed on global ones (:func:`placed`): the constrained local components of one node's
translation (or rotation) vector, a_k . u = (sum of masters) with a_k = R[:, k], are solved for as many
global components as there are rows, chosen where the rows' block is best conditioned; the node's other
global components stay free and enter as masters.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from .mesh import NDOF
from .model import Model


def to_global(A: np.ndarray, R) -> np.ndarray:
    """Element matrices ``A`` (n_cells, 6 m, 6 m) on local DOFs turned to global ones (T A T^T)."""
    if R is None:
        return A
    nc, nd, _ = A.shape
    b = nd // 3
    B = A.reshape(nc, b, 3, b, 3)
    return np.einsum("ij,cajbk,lk->caibl", R, B, R, optimize=True).reshape(nc, nd, nd)


def _local_terms(dof: int, R) -> list:
    """A local DOF as global terms [(global dof, coefficient)]: u_l[k] = sum_j R[j, k] u_g[j]."""
    node, c = divmod(int(dof), NDOF)
    block, k = divmod(c, 3)
    base = NDOF * node + 3 * block
    return [(base + j, float(R[j, k])) for j in range(3) if abs(R[j, k]) > 1e-15]


def _slaves(A: np.ndarray) -> list:
    """The global components (as many as A's rows) whose columns of A are best conditioned."""
    r = A.shape[0]
    return list(max(combinations(range(3), r), key=lambda J: abs(np.linalg.det(A[:, list(J)]))))


def idle_dofs(local: Model, K, M) -> np.ndarray:
    """The DOFs of ``local`` (assembled ``K``, ``M``) no element touches and no constraint holds: held in
    place when the model is placed (a drilling rotation left free in local axes would mix with the
    others' in global ones and float)."""
    from .constraints import build_reduction

    red = build_reduction(local, K, M)
    held = np.zeros(local.n_dof, dtype=bool)
    held[red.independent] = True
    held[list(local.fixed)] = True
    held[[s for s, _ in local.mpcs]] = True
    return np.flatnonzero(~held)


def placed(local: Model, R, origin, first_node: int, idle=()) -> tuple:
    """(nodes (n, 3) in global coordinates, fixed global DOFs, mpcs on global DOFs) of model ``local``
    whose nodes become global nodes ``first_node`` onwards, placed by rotation ``R`` and ``origin``
    [m]; ``idle`` (:func:`idle_dofs`): local DOFs held as if fixed. Its element sets are added by the
    caller with ``frame=R`` and connectivities shifted by ``first_node``."""
    R = np.asarray(R, float)
    shift = NDOF * int(first_node)
    nodes = np.asarray(origin, float) + local.nodes @ R.T
    rows: dict = {}  # (node, block) -> [(local component, [(local master dof, c)])]
    for d in set(local.fixed) | {int(i) for i in idle}:
        node, c = divmod(int(d), NDOF)
        rows.setdefault((node, c // 3), []).append((c % 3, []))
    for s, terms in local.mpcs:
        node, c = divmod(int(s), NDOF)
        rows.setdefault((node, c // 3), []).append((c % 3, terms))
    fixed, mpcs = set(), []
    for (node, block), entries in rows.items():
        A = np.array([R[:, k] for k, _ in entries])
        J = _slaves(A)
        O = [j for j in range(3) if j not in J]
        Ainv = np.linalg.inv(A[:, J])
        base = shift + NDOF * node + 3 * block
        rhs = []  # per row: global terms of its masters
        for _, terms in entries:
            row: dict = {}
            for m, c in terms:
                for g, a in _local_terms(m, R):
                    row[g + shift] = row.get(g + shift, 0.0) + c * a
            rhs.append(row)
        for i, j in enumerate(J):
            out: dict = {}
            for r, row in enumerate(rhs):
                for g, c in row.items():
                    out[g] = out.get(g, 0.0) + Ainv[i, r] * c
            for o in O:
                coef = -sum(Ainv[i, r] * A[r, o] for r in range(len(entries)))
                out[base + o] = out.get(base + o, 0.0) + coef
            terms = [(g, c) for g, c in out.items() if abs(c) > 1e-14]
            if terms:
                mpcs.append((base + j, terms))
            else:
                fixed.add(base + j)
    return nodes, fixed, mpcs
