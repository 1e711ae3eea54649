"""Success ratio of parameter error localisation (thesis section 5.3.1); the studies' measurement
noise is :func:`pcbdyn.testdata.noise.add_noise` (section 5.3.3)."""

from __future__ import annotations

import numpy as np


def success_ratio(detected, true_errors) -> float:
    """SR = N_rdet / max(N_det, N_err) * 100 % (thesis eq. 5.65): N_rdet true errors among the
    N_det detected parameters, N_err introduced errors. Both sets are parameter indices or names."""
    detected, true_errors = set(np.atleast_1d(detected).tolist()), set(np.atleast_1d(true_errors).tolist())
    if not true_errors:
        raise ValueError("true_errors is empty: the success ratio needs at least one introduced error")
    return 100.0 * len(detected & true_errors) / max(len(detected), len(true_errors))


def success_statistics(ratios):
    """Mean and sample standard deviation of success ratios over random shots (thesis eq. 5.66)."""
    r = np.asarray(ratios, float)
    return float(r.mean()), float(r.std(ddof=1)) if r.size > 1 else 0.0
