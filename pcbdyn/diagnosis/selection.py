"""What a selection of effects is and how it is weighed (issue 7, step 5): the effects chosen with their
magnitudes and the declared parameters fitted with them, the chi^2 and the information criterion after
each step, and the penalty one more effect must pay (the criterion :mod:`.select` explains).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.stats import chi2 as chi2_dist

from ..problems.error_budget import noise_explains, variance_left
from .fitting import Fit

#: probability that noise alone makes one of the candidates look like an effect (family-wise)
ALPHA = 0.01


@dataclass
class Selection:
    """``chosen``: candidate indices in the order found; ``values``: their magnitudes (SI) and
    ``sigma`` their standard deviations (``cov`` their covariance); ``p``: the declared parameters estimated with them;
    ``chi2[s]``, ``criterion[s]``: after step s (s = 0: the declared parameters alone);
    ``state``: the final :class:`.residual.State`; ``frequencies``: the paired model frequencies of
    the first configuration."""

    chosen: list = field(default_factory=list)
    values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sigma: np.ndarray = field(default_factory=lambda: np.zeros(0))
    cov: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    p: np.ndarray = field(default_factory=lambda: np.zeros(0))
    chi2: list = field(default_factory=list)
    criterion: list = field(default_factory=list)
    state: object = None

    @property
    def frequencies(self) -> np.ndarray:
        return self.state.configs[0].f_a

    def within_noise(self, n_free: int, alpha: float = ALPHA) -> bool:
        """Whether the last step's chi^2 is what noise gives with probability above ``alpha`` (the
        chi-square test of thesis section 5.2.3), ``n_free`` the rows less the declared parameters."""
        return noise_explains(self.chi2[-1], n_free - len(self.chosen), alpha)


def penalty(n_obs: int, n_candidates: int, alpha: float = ALPHA) -> float:
    """Criterion cost of one more effect: max(ln n, chi^2_1 quantile at 1 - alpha / P)."""
    return max(np.log(n_obs), float(chi2_dist.isf(alpha / max(n_candidates, 1), 1)))


def adopt(sel: Selection, idx: list, fit: Fit, pen: float) -> Selection:
    """``sel`` updated in place to the effects ``idx`` estimated by ``fit`` (one more step)."""
    n_par = np.size(fit.p)
    sel.chosen, sel.values, sel.p, sel.state = list(idx), fit.values, fit.p, fit.state
    sel.cov = fit.cov[n_par:, n_par:]
    sel.sigma = np.sqrt(np.clip(np.diag(sel.cov), 0.0, None))
    sel.chi2.append(fit.chi2)
    sel.criterion.append(fit.chi2 + len(idx) * pen)
    return sel


def worth(chi2_before, chi2_after, n, k, pen) -> bool:
    """The drop exceeds the penalty in stated noise units and in units of the variance left."""
    drop = chi2_before - chi2_after
    return drop > pen and drop / variance_left(chi2_after, n, k) > pen
