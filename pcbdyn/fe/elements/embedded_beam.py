"""Embedded beam: a two-node beam (:mod:`.beam`) whose ends are points inside host shell cells,
each end's translations and rotations interpolated from the cell's nodes with the shell's shape
functions (a tie that adds no stiffness of its own): K = T^T K_beam T, M = T^T M_beam T with T
the (12, 6 nodes) interpolation of the two ends. A cell lists the host nodes of both ends (a
triangle's repeated node with weight 0 is allowed).

Inside a Mindlin shell's cell w and theta are interpolated independently: a section with
``linear_bending`` (w and theta linear, as the host's) suits it; a Hermite cubic between the
interpolated end values takes their mismatch for curvature (a rib across the six-part card was
1 % too stiff at 6.75 mm against 1.7 mm, with linear bending 0.4 %)."""

from __future__ import annotations

import numpy as np

from ..model import ModelError
from . import beam


def matrices(xyz: np.ndarray, prop):
    n_cells, nn, _ = xyz.shape
    W = np.asarray(prop.weights, float)
    if W.shape != (n_cells, 2, nn):
        raise ModelError(f"EmbeddedBeamProperty.weights must be (n_cells, 2, {nn}) for {n_cells} cells, got {W.shape}")
    ends = np.einsum("cen,cnk->cek", W, xyz)
    Kb, Mb = beam.matrices(ends, prop.beam)
    T = np.einsum("cen,ab->ceanb", W, np.eye(6)).reshape(n_cells, 12, 6 * nn)
    Tt = T.transpose(0, 2, 1)
    return Tt @ (Kb @ T), Tt @ (Mb @ T)
