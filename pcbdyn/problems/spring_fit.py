"""Step 2 of the wedge-lock fit (thesis section 7.4.2, Tables 7.10-7.11 and 7.14-7.15, Figs. 7.36-7.39):
the guides as rotational springs, their stiffness (one shared, or one per guide) updated on a log scale
from the resonance frequencies (eqs. 3.2-3.3), bounded (eqs. 4.44-4.48), re-paired at every iteration,
with its uncertainty from the equations in units of the stated noise (eq. 4.28). The fit is
:func:`.fit.fit`: scanned between the extremes first, with the shapes in the objective where the
frequencies cannot tell the guides apart (a nearly symmetric card).

Every test mode's relative standard deviation ``sigma_pct`` weighs its row, so chi^2 sums
((f_model - f_test) / (sigma f_test))^2 over the paired modes; the same sum judges the extremes."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.stats import f as f_dist

from ..updating.iteration import build_equations
from ..updating.solvers import covariance
from . import guides
from .error_budget import variance_left
from .fit import DEFAULT_NOISE, configurations, fit
from .problem import UpdateProblem
from .run import correlation_state

#: significance level of the tests that add a parameter (springs rather than clamped, one stiffness
#: per guide rather than one shared)
ALPHA = 0.05


def chi2(pairs_per_config, sigma_pct, modes=None) -> tuple:
    """(chi^2, number of modes) over the pairs (per configuration a list of dicts with test_mode and
    df_pct) in units of ``sigma_pct`` (per configuration {test mode: %}); ``modes``: per configuration
    the test modes to count (default all paired)."""
    total, n = 0.0, 0
    for k, (pairs, sig) in enumerate(zip(pairs_per_config, sigma_pct)):
        for q in pairs:
            if modes is None or q["test_mode"] in modes[k]:
                total += (q["df_pct"] / sig[q["test_mode"]]) ** 2
                n += 1
    return total, n


def significance(chi2_simple: float, chi2_rich: float, n: int, extra: int, k_rich: int, alpha: float = ALPHA) -> dict:
    """Does a model with ``extra`` more parameters (``k_rich`` in all) explain ``n`` modes significantly
    better? The extra-sum-of-squares F test of nested least-squares models: F = (chi2_simple -
    chi2_rich) / extra / s^2, s^2 the rich model's residual variance per degree of freedom, at least the
    stated noise (1). A drop the noise, or the errors the rich model cannot explain either, would give
    as often as not is no reason to prefer it."""
    dof = n - k_rich
    if dof < 1:
        return {"F": None, "critical": None, "p_value": None, "dof": [extra, dof], "significant": False}
    s2 = variance_left(chi2_rich, n, k_rich)
    F = max(chi2_simple - chi2_rich, 0.0) / extra / s2
    return {"F": float(F), "critical": float(f_dist.isf(alpha, extra, dof)), "p_value": float(f_dist.sf(F, extra, dof)),
            "dof": [extra, dof], "significant": bool(f_dist.sf(F, extra, dof) < alpha)}


@dataclass
class SpringFit:
    """One fitted spring model: ``groups`` {parameter: [fixtures]}, the ``problem``, the driver's
    ``result`` (:class:`pcbdyn.updating.driver.UpdateResult`), the correlation ``before`` (at the
    start) and ``after`` (:func:`~.run.correlation_state`), ``cov`` of ln k, the fit's frequency ``chi2`` over
    ``n`` modes, ``notes`` (the fit's details: its verdict, bounds reached, stiffness combinations the data
    do not determine, configurations made worse, other starts) and the :class:`~.fit.Fit` itself."""

    groups: dict
    problem: UpdateProblem
    result: object
    before: list
    after: list
    cov: np.ndarray
    chi2: float
    n: int
    notes: list = field(default_factory=list)
    fit: object = None

    @property
    def max_freq_error_pct(self) -> float | None:
        errors = [s["max_freq_error_pct"] for s in self.after if s["max_freq_error_pct"] is not None]
        return max(errors) if errors else None

    @property
    def values(self) -> dict:
        """{parameter: k [N*m/rad/m]}."""
        return self.problem.values(self.result.p)

    @property
    def factors(self) -> dict:
        """{parameter: exp(sigma of ln k)}: k / factor .. k * factor is its 1-sigma range."""
        with np.errstate(over="ignore"):  # a stiffness the data leave open: an infinite factor
            return {n: float(np.exp(np.sqrt(max(v, 0.0)))) for n, v in zip(self.problem.names, np.diag(self.cov))}

    def by_fixture(self, p) -> dict:
        """{fixture name: k} of parameter values ``p``."""
        return {f: float(v) for (_, fixtures), v in zip(self.groups.items(), np.asarray(p, float)) for f in fixtures}

    def k_rot(self) -> dict:
        """{fixture: {value [N*m/rad/m], factor_1sigma, parameter, bound_hit}}."""
        lo, hi = self.problem.bounds
        out = {}
        for j, (name, fixtures) in enumerate(self.groups.items()):
            v = float(self.result.p[j])
            hit = "lower" if np.isclose(v, lo[j], rtol=1e-6) else "upper" if np.isclose(v, hi[j], rtol=1e-6) else None
            for f in fixtures:
                out[f] = {"value": v, "factor_1sigma": self.factors[name], "parameter": name, "bound_hit": hit}
        return out


class SpringModel:
    """The board with its guides as springs (``groups``: :func:`.guides.spring_groups`) against ``tests``
    [(configuration, Modes)], within ``bounds`` [N*m/rad/m]; ``noise`` (frequency %, shape %; None where not
    stated) and the model's mesh error ``mesh_pct`` (per configuration {test mode: %}) weigh each mode, whose
    total ``sigma_pct`` (per configuration {test mode: %}, every mode) the chi^2 of :func:`chi2` uses;
    pairing by MAC with shapes and by mode number without."""

    def __init__(self, board, tests, groups: dict, bounds: tuple, sigma_pct: list, noise=(None, None),
                 mesh_pct=None, mesh_size=None, min_mac: float = 0.5):
        self.groups, self.sigma_pct, self.noise, self.min_mac = groups, sigma_pct, noise, min_mac
        k0 = float(np.sqrt(bounds[0] * bounds[1]))
        self.board = guides.springs(board, groups, {n: k0 for n in groups}, bounds)
        self.problem = UpdateProblem(self.board, list(groups), mesh_size=mesh_size)
        self.tests = [(0, c, m) for c, m in tests]
        self.mesh_pct = None if mesh_pct is None else [
            np.array([per.get(i + 1, 0.0) for i in range(m.n_modes)]) for per, (_, m) in zip(mesh_pct, tests)]
        model = None if mesh_pct is None else (self.mesh_pct, [None] * len(tests))
        self.configs = configurations(self.problem, self.tests, "freq", *self._noise(), model, min_mac)

    def _noise(self) -> tuple:
        return tuple(v if v is not None else d for v, d in zip(self.noise, DEFAULT_NOISE))

    def state(self, p) -> list | None:
        """:func:`~.run.correlation_state` at ``p``, None when no test mode pairs there."""
        try:
            return correlation_state(self.configs, p)
        except ValueError:
            return None

    def chi2(self, state, modes=None) -> tuple:
        return chi2([s["pairs"] for s in state], self.sigma_pct, modes)

    def scan(self, ks) -> list:
        """The states at every shared stiffness of ``ks`` (all parameters equal)."""
        return [self.state(np.full(len(self.groups), float(k))) for k in ks]

    def fit(self, p0, max_iter: int = 20, progress=None) -> SpringFit:
        """:func:`.fit.fit` from ``p0`` on a log scale (scanned first; it stops when the stiffness moves less
        than 0.5 %, eq. 7.3, or the residue stalls, eq. 7.4), the covariance of ln k at the result from the
        equations fitted."""
        self.problem.p0 = np.asarray(p0, float)
        r = fit(self.problem, self.tests, noise=self.noise, model_pct=self.mesh_pct, mesh_check=True,
                max_iter=max_iter, tol_freq_pct=0.0, min_mac=self.min_mac, progress=progress)
        (A, b), _, _ = build_equations(r.configs, r.p)
        total, n = self.chi2(r.after)
        return SpringFit(self.groups, self.problem, r.result, r.before, r.after, covariance(A, b, stated=True),
                         total, n, r.details, r)
