"""Vectorised sparse assembly of global K and M, for the whole model or a subset of element sets.

Subset assembly is what makes parameter sensitivities cheap: dK/dp of a parameter that
touches one set needs only that set's element matrices.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .elements import kernel
from .mesh import element_dofs


def element_matrices(model, name: str, prop=None):
    """Element K and M of set ``name`` (optionally with another property), shape (n_cells, nd, nd)."""
    es = model.sets[name]
    return kernel(es.etype)(model.nodes[es.conn], es.prop if prop is None else prop)


def _triplets(conn: np.ndarray):
    dofs = element_dofs(conn)
    nd = dofs.shape[1]
    return np.repeat(dofs, nd, axis=1).ravel(), np.tile(dofs, (1, nd)).ravel()


def scatter(n_dof: int, conn: np.ndarray, Ae: np.ndarray) -> sp.csr_matrix:
    """Sum element matrices ``Ae`` (n_cells, nd, nd) of cells ``conn`` into an n_dof x n_dof CSR matrix."""
    rows, cols = _triplets(conn)
    return sp.csr_matrix((Ae.ravel(), (rows, cols)), shape=(n_dof, n_dof))


def assemble(model, sets=None, props=None):
    """Global (K, M) as CSR matrices over all 6 * n_nodes DOFs, before constraints.

    ``sets``: names of the element sets to include (default: all). ``props``: optional
    {set name: property} overrides, used to evaluate a perturbed set without copying the model.
    """
    names = list(model.sets) if sets is None else list(sets)
    props = props or {}
    rows, cols, kv, mv = [], [], [], []
    for name in names:
        es = model.sets[name]
        if len(es.conn) == 0:
            continue
        Ke, Me = element_matrices(model, name, props.get(name))
        r, c = _triplets(es.conn)
        rows.append(r)
        cols.append(c)
        kv.append(Ke.ravel())
        mv.append(Me.ravel())
    n = model.n_dof
    if not rows:
        return sp.csr_matrix((n, n)), sp.csr_matrix((n, n))
    r, c = np.concatenate(rows), np.concatenate(cols)
    K = sp.csr_matrix((np.concatenate(kv), (r, c)), shape=(n, n))
    M = sp.csr_matrix((np.concatenate(mv), (r, c)), shape=(n, n))
    return K, M
