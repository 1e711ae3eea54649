"""Degree-of-freedom numbering shared by every element: 6 DOF per node, in global axes."""

import numpy as np

NDOF = 6
DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")


def dof_index(nodes, dofs=None) -> np.ndarray:
    """Global DOF numbers of ``nodes`` (int or array) for the local DOFs ``dofs``.

    ``dofs`` are names from :data:`DOF_NAMES` or integers 0-5 (default: all six).
    The result has shape ``(len(nodes), len(dofs))``, flattened when one node is given.
    """
    scalar = np.ndim(nodes) == 0
    nodes = np.atleast_1d(np.asarray(nodes, dtype=np.int64))
    if dofs is None:
        local = np.arange(NDOF)
    else:
        local = np.array(
            [DOF_NAMES.index(d) if isinstance(d, str) else int(d) for d in np.atleast_1d(dofs)],
            dtype=np.int64,
        )
    out = NDOF * nodes[:, None] + local[None, :]
    return out.ravel() if scalar else out


def element_dofs(conn: np.ndarray) -> np.ndarray:
    """Global DOF numbers of each element, shape ``(n_elements, 6 * nodes_per_element)``."""
    conn = np.asarray(conn, dtype=np.int64)
    return (NDOF * conn[:, :, None] + np.arange(NDOF)).reshape(conn.shape[0], -1)
