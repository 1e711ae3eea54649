"""Two effects that one body brings to one place (issue 37: a heat sink is a region's stiffness and its
mass, a bracket a mass and a spring at one point, a part a mass and a rotary inertia). Alone, each half
may explain the residual so poorly that forward selection one effect at a time takes neither, so the
search also tries both as one addition (:class:`Halves`, ranked by the chi^2 their two columns remove
together), and the local search moves a body found as one (:func:`body_moves`). A kind names the
kinds found together with it in ``together`` (:mod:`.catalogue`)."""

from __future__ import annotations

import numpy as np


def together(a, b) -> bool:
    """Candidates ``a`` and ``b`` are the two halves of one body: kinds found together, same nodes."""
    return b.kind in getattr(a.spec, "together", ()) and np.array_equal(a.nodes, b.nodes)


class Halves:
    """The pairs of candidates that can be added in one step (:func:`together`); ``group``: their kinds."""

    def __init__(self, candidates):
        on = {(c.kind, c.nodes.tobytes()): j for j, c in enumerate(candidates)}
        pairs = {tuple(sorted((i, on[key]))) for i, c in enumerate(candidates) for other in getattr(c.spec, "together", ())
                 if (key := (other, c.nodes.tobytes())) in on}
        self.pairs = np.array(sorted(pairs), dtype=np.int64).reshape(-1, 2)
        self.group = np.array([f"{candidates[i].kind}+{candidates[j].kind}" for i, j in self.pairs])

    def shortlist(self, A_p, r_p, scale, lower, chosen, per_group: int) -> list:
        """The ``per_group`` pairs of each pair of kinds best by :meth:`gains`."""
        if not self.pairs.size:
            return []
        gain = self.gains(A_p, r_p, scale, lower, chosen)
        return [tuple(int(k) for k in self.pairs[m]) for m in per_kind(gain, self.group, per_group)]

    def gains(self, A_p, r_p, scale, lower, chosen) -> np.ndarray:
        """The chi^2 each pair's two columns ``A_p`` (projected off the held ones, as ``r_p``) remove
        together, -inf where a value is unphysical (``lower``) or a half ``chosen``: the linear score of
        :func:`.select.search` for an addition of two columns."""
        a, b = A_p[:, self.pairs[:, 0]], A_p[:, self.pairs[:, 1]]
        g11, g22, g12 = (np.einsum("ij,ij->j", x, y) for x, y in ((a, a), (b, b), (a, b)))
        c1, c2 = a.T @ r_p, b.T @ r_p
        det = g11 * g22 - g12**2
        ok = det > 1e-9 * g11 * g22
        det = np.where(ok, det, 1.0)
        v1, v2 = (g22 * c1 - g12 * c2) / det, (g11 * c2 - g12 * c1) / det
        gain = np.where(ok, v1 * c1 + v2 * c2, -np.inf)
        i, j = self.pairs.T
        gain[(v1 * scale[i] < lower[i]) | (v2 * scale[j] < lower[j]) | np.isin(i, chosen) | np.isin(j, chosen)] = -np.inf
        return gain


def bodies(candidates, idx) -> list:
    """[(a, b)]: positions in ``idx`` of the two halves of each body found (:func:`together`)."""
    return [(a, b) for a, i in enumerate(idx) for b, j in enumerate(idx) if a < b and together(candidates[i], candidates[j])]


def body_moves(candidates, idx, found, neighbours) -> list:
    """The swaps that move both halves of each body ``found`` (:func:`bodies`) to one new place: each
    move of the first with the second's kind there (``neighbours.half``, made on demand). A body's
    halves share their footprint (a heat sink's mass and stiffness), so they walk as one."""
    out = []
    for a, b in found:
        for j in neighbours(idx[a]):
            j2 = neighbours.half(j, candidates[idx[b]].kind)
            if j2 is not None and j not in idx and j2 not in idx:
                sw = list(idx)
                sw[a], sw[b] = j, j2
                out.append(sw)
    return out


def per_kind(gain, kinds, n: int) -> np.ndarray:
    """The ``n`` best finite-gain columns of every kind."""
    out = []
    for k in np.unique(kinds):
        idx = np.flatnonzero((kinds == k) & np.isfinite(gain))
        out.append(idx[np.argsort(-gain[idx])[:n]])
    return np.concatenate(out) if out else np.zeros(0, dtype=np.int64)
