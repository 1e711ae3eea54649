"""Which modes a test in z sees: a board's in-plane modes (one on soft standoffs slides on them) move
nothing out of its plane, and a vibrometer or z accelerometers do not measure them."""

from __future__ import annotations

import numpy as np

#: modes solved beyond those tested, so that the in-plane ones can be left out
EXTRA_MODES = 6
#: the least share of a mode's translations out of the plane for a z test to measure it
MIN_BENDING = 0.3


def bending_share(u) -> np.ndarray:
    """Per mode, the share of the translations ``u`` (n_nodes, 3, n_modes) along z."""
    return np.linalg.norm(u[:, 2], axis=0) / np.linalg.norm(u.reshape(-1, u.shape[-1]), axis=0)
