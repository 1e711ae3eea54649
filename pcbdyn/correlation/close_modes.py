"""Close modes: measured modes whose frequencies the test cannot tell apart, and their shapes turned
onto a model's within their common plane."""

from __future__ import annotations

import numpy as np

from .pairing import clusters

#: measured modes whose frequencies differ by less than this many standard deviations of their
#: difference form a close group (:func:`close_groups`)
CLOSE_SIGMAS = 3.0


def close_groups(f, sd) -> list:
    """Groups (index tuples) of the modes of frequencies ``f`` (their measurement noise ``sd``, same
    unit) that lie within :data:`CLOSE_SIGMAS` of their neighbours. A perturbation too small for the
    frequencies to show couples two such modes about as strongly as their gap separates them, so it
    turns them within their plane by an angle of order one (thesis eqs. 3.8-3.12: the coupling over
    the eigenvalue gap): the test determines their plane, not each shape within it. The noise, not a
    model's wider error budget: modes a few percent apart on a coarse mesh still differ in shape, and
    their turn is what a local effect shows first (a stiffener's, dev seeds 9 and 14)."""
    return [tuple(g) for g in clusters(f, CLOSE_SIGMAS, sd) if len(g) > 1]


def align_close(x, u, groups) -> np.ndarray:
    """The measured shapes ``x`` (points x modes) with each close group's turned within its own span onto
    the model shapes ``u`` paired column by column: the orthogonal rotation of the unit-scaled measured
    shapes that best matches the unit-scaled model shapes (orthogonal Procrustes), each column keeping
    its length."""
    if not groups:
        return x
    x = np.array(x, float)
    for g in map(list, groups):
        n, nu = np.linalg.norm(x[:, g], axis=0), np.linalg.norm(u[:, g], axis=0)
        W, _, Vt = np.linalg.svd((x[:, g] / n).T @ (u[:, g] / nu))
        x[:, g] = (x[:, g] / n) @ (W @ Vt) * n
    return x
