"""Fixtures of the vibration tests; the plates themselves are in vibe_plates.py."""

import pytest
from vibe_plates import A, B, solve, write_plate


@pytest.fixture(scope="module")
def steinberg_plate(tmp_path_factory):
    """The plate meshed at 5 mm with TINY parts at Steinberg's three positions: the centre (U1),
    the half/quarter point (U2) and the quarter/quarter point (U3); modes up to 4 kHz."""
    a, b = A * 1e3, B * 1e3
    path = write_plate(tmp_path_factory.mktemp("plate"), 5.0,
                       [("U1", a / 2, b / 2), ("U2", a / 2, b / 4), ("U3", a / 4, b / 4)])
    return solve(path, 4000.0)
