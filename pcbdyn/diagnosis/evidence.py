"""The evidence map: where the residual points once the declared parameters are fitted."""

from __future__ import annotations

import numpy as np

def evidence(res, state, cands) -> dict:
    """{kind: (xy, chi^2 removed)} for the node kinds: the linear chi^2 drop of a candidate at each
    node, the declared parameters projected out (the map of where the residual points)."""
    out = {}
    for name in ("point_mass", "ground_spring"):
        idx = [i for i, c in enumerate(cands) if c.kind == name]
        if not idx:
            continue
        A = res.effect_columns(state, [cands[i] for i in idx])
        P = res.param_columns(state)
        if P.shape[1]:
            Q, _ = np.linalg.qr(P)
            A, r = A - Q @ (Q.T @ A), state.r - Q @ (Q.T @ state.r)
        else:
            r = state.r
        n2 = np.einsum("ij,ij->j", A, A)
        gain = np.where(n2 > 0, (A.T @ r) ** 2 / np.where(n2 > 0, n2, 1.0), 0.0)
        gain[(A.T @ r) < 0] = 0.0  # negative magnitudes are not physical
        out[name] = (np.array([cands[i].at for i in idx]), gain)
    return out
