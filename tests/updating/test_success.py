"""Success ratio (thesis eqs. 5.65-5.66) and the simulated noise (eqs. 5.72-5.74, testdata.noise)."""

import numpy as np
import pytest

from pcbdyn.testdata import add_noise
from pcbdyn.updating import success_ratio, success_statistics


def test_success_ratio_thesis_example():
    """Section 5.3.1: errors on E5-E8, detected E5, E6, E8, E9, E18 -> 3 / 5 = 60 %."""
    assert success_ratio(["E5", "E6", "E8", "E9", "E18"], ["E5", "E6", "E7", "E8"]) == pytest.approx(60.0)
    assert success_ratio(["E5", "E6"], ["E5", "E6", "E7", "E8"]) == pytest.approx(50.0)
    assert success_ratio([4, 5, 6, 7], [4, 5, 6, 7]) == 100.0
    with pytest.raises(ValueError, match="true_errors"):
        success_ratio([1], [])


def test_statistics_and_noise():
    mean, std = success_statistics([100, 50, 75, 75])
    assert mean == 75 and std == pytest.approx(np.std([100, 50, 75, 75], ddof=1))
    f = np.linspace(10, 100, 2000)
    noisy = add_noise(f, 2.0, seed=0)
    rel = noisy / f - 1
    assert np.all(np.abs(rel) <= 0.02) and rel.max() > 0.019 and rel.min() < -0.019
    H = np.exp(1j * np.linspace(0, 3, 50))
    assert np.allclose(np.angle(add_noise(H, 5.0, seed=1)), np.angle(H))
