"""The noise's share of the error budget (:mod:`pcbdyn.problems.error_budget`): the chi-square test that
diagnose, calibrate and wedgelock share, checked against the chi-square law itself."""

import numpy as np
import pytest

from pcbdyn.problems.error_budget import noise_explains, noise_probability, variance_left


def test_the_noise_probability_is_the_chi_square_law():
    """Over two degrees of freedom chi^2 is exponential: P(chi^2 >= x) = exp(-x / 2)."""
    for x in (0.1, 2.0, 9.21):
        assert noise_probability(x, 2) == pytest.approx(np.exp(-x / 2), rel=1e-12)


def test_noise_alone_is_explained_at_the_stated_rate():
    """Fits whose rows are unit normal noise (40 rows, 3 unknowns fitted away) pass the test at
    alpha = 5 % in 95 % of 4000 draws (binomial sigma 0.34 %); rows 1.5 times the stated noise fail it
    in most draws."""
    rng = np.random.default_rng(37)
    n, k, draws, alpha = 40, 3, 4000, 0.05
    chi2 = (rng.standard_normal((draws, n - k)) ** 2).sum(axis=1)
    rate = np.mean([noise_explains(c, n - k, alpha) for c in chi2])
    assert rate == pytest.approx(1 - alpha, abs=0.012)
    assert np.mean([noise_explains(2.25 * c, n - k, alpha) for c in chi2]) < 0.2


def test_the_variance_left_is_never_below_the_stated_noise():
    """A fit within the noise leaves the stated variance (1); one whose rows are twice the stated noise
    leaves four times it per degree of freedom."""
    assert variance_left(30.0, 40, 3) == 1.0
    assert variance_left(4.0 * 37, 40, 3) == pytest.approx(4.0)
    assert variance_left(10.0, 3, 5) == 10.0  # no degree of freedom left: the whole chi^2 per row
