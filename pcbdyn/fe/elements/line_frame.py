"""Local frames of 2-node line cells (beams, edge springs): an axis along the cell and a second
axis from a reference vector projected normal to it."""

from __future__ import annotations

import numpy as np

from ..model import ModelError


def line_axes(xyz: np.ndarray, reference, what: str, hint: str):
    """Lengths (n,), unit axes (n, 3) from node 1 to node 2, and the unit part of ``reference``
    normal to each axis (n, 3).

    ``what`` names the cells and ``hint`` the fix in the errors raised for coincident nodes or a
    reference vector that is zero or parallel to a cell.
    """
    d = xyz[:, 1] - xyz[:, 0]
    L = np.linalg.norm(d, axis=1)
    if np.any(L <= 0):
        bad = np.flatnonzero(L <= 0)[:5]
        raise ModelError(f"{what} cells {bad.tolist()} have coincident nodes (zero length)")
    axis = d / L[:, None]
    v = np.asarray(reference, dtype=float)
    nv = np.linalg.norm(v)
    ref = v[None, :] - (axis @ v)[:, None] * axis
    nr = np.linalg.norm(ref, axis=1)
    if nv == 0 or np.any(nr < 1e-6 * nv):
        bad = np.flatnonzero(nr < 1e-6 * max(nv, 1e-300))[:5]
        raise ModelError(f"{tuple(v)} is zero or parallel to the axis of {what} cells {bad.tolist()}: {hint}")
    return L, axis, ref / nr[:, None]
