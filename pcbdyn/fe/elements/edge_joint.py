"""Springs per unit length between two coincident lines of element edges (4-node cells a1, a2, b1, b2,
b1 at a1 and b2 at a2): the joint of two plates along an edge they share, each plate on its own copy of
the edge's nodes (a rotational stiffness about the edge between the two plates, the other DOFs tied by
constraints). They act on the relative motion u_b - u_a in the edge frame of :mod:`.edge_spring`, with
the same consistent integration: K = [[Ke, -Ke], [-Ke, Ke]], Ke the edge spring of line a1-a2. No mass.
"""

from __future__ import annotations

import numpy as np

from . import edge_spring


def matrices(xyz: np.ndarray, prop):
    """K (n_cells, 24, 24) in global axes for cells ``xyz`` (n_cells, 4, 3); M is zero."""
    xyz = np.asarray(xyz, dtype=float)
    Ke, _ = edge_spring.matrices(xyz[:, :2], prop)
    K = np.block([[Ke, -Ke], [-Ke, Ke]])
    return K, np.zeros_like(K)
