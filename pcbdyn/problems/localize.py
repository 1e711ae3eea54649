"""Error localisation among a structure's parameters from its tests (thesis ch. 5): the evidence of the
subset selection, the equations redrawn with the stated noise, and the FBM residual map."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..testdata.noise import add_noise
from ..updating import matching
from ..updating.indicators import fbm_residuals
from ..updating.iteration import build_equations
from ..updating.study import localise
from ..updating.subset import EXPLAIN_TOL, explain_tol_from_noise, tls_qrf
from ..updating.weighting import NOISE_REDRAWS, tls_column_weight_from_noise


def evidence(method, A, b, names, rank=None, alpha=0.8, redraws=()) -> tuple:
    """(dict for JSON, the TLS/QR-F Subset). The 5.2.3 check, condition curve and rank always come
    from TLS/QR-F; selection and solution from ``method``. ``redraws``: equations rebuilt with the
    stated noise drawn again (:func:`noise_redraws`); with them b is weighted for TLS by the errors
    the noise makes (else eq. 4.43 with k_A = k_b) and b counts as explained up to the part of
    those errors outside range(A)."""
    r = None if rank is None else (rank if rank >= 0 else A.shape[1] + rank)
    t_b = tls_column_weight_from_noise(A, b, redraws) if redraws else None
    tol = explain_tol_from_noise(A, b, redraws) if redraws else EXPLAIN_TOL
    tls = tls_qrf(A, b, rank=r, alpha=alpha, t_b=t_b, explain_tol=tol)
    if method == "tls-qrf":
        sel, order, ratios = tls.selected, tls.order, tls.descending_ratio
    else:
        sel, order, ratios = localise(method, A, b, rank, t_b), np.zeros(0, int), np.zeros(0)
    x = np.zeros(A.shape[1])
    if sel.size:
        x[sel] = np.linalg.lstsq(A[:, sel], b, rcond=None)[0]
    data = {
        "method": method,
        "tls_weight": t_b,
        "explain_tol_pct": 100.0 * tol,
        "selected": [names[i] for i in sel],
        "order": [names[i] for i in order],
        "descending_ratio": [float(v) for v in ratios],
        "solution": {names[i]: float(x[i]) for i in sel},
        "rank": int(tls.rank),
        "condition_curve": [float(v) if np.isfinite(v) else None for v in tls.condition_curve],
        "explains_data": bool(tls.explains_data),
        "out_of_range_pct": 100.0 * float(tls.out_of_range),
        "message": tls.message,
    }
    return data, tls


def noise_redraws(problem, tests, eq_type, matching_kind, shape, freq_pct, shape_pct, seed: int = 0) -> list:
    """Equations (A_d, b_d) rebuilt from the measured data ``tests`` [(configuration, Modes)] with the
    stated noise drawn again (eqs. 5.72-5.73), those that pair like the data (``shape`` of A): what
    the noise does to the equations, for the TLS weight of b and the 5.2.3 check."""
    rng = np.random.default_rng(seed)
    redraws = []
    for _ in range(NOISE_REDRAWS):
        cfgs = [problem.configuration(name, replace(
            m, frequencies=add_noise(m.frequencies, freq_pct or 0.0, rng),
            shapes=None if m.shapes is None else add_noise(m.shapes, shape_pct or 0.0, rng)), eq_type,
            matching=matching_kind) for name, m in tests]
        (Ad, bd), _, _ = build_equations(cfgs, problem.p0)
        if Ad.shape == shape:
            redraws.append((Ad, bd))
    return redraws


def fbm_map(cfg, state) -> tuple:
    """(values, index of the peak): FBM residual forces (eq. 5.2) of a configuration's measured modes at
    its measured DOFs: the shapes are expanded to the model (eq. 2.25), the residuals read back at the
    measured points (the expansion leaves none elsewhere), scaled per mode to a maximum of 1 and summed
    over the modes (as thesis Fig. 5.1)."""
    K, M, used = state["K"], state["M"], state["used"]
    om = 2 * np.pi * np.asarray(cfg.f_x, float)[used]
    phi = matching.expand(K, M, cfg.P, np.asarray(cfg.phi_x)[:, used], om)
    res = np.abs(np.asarray(cfg.P @ fbm_residuals(K, M, om, phi)))
    peak = res.max(axis=0)
    values = (res / np.where(peak > 0, peak, 1.0)).sum(axis=1)
    return values, int(np.argmax(values))
