"""Steinberg's check of parts: his published sample problem, and hand-computed lives and damage.

Published worked example (the only one with numbers that could be found and checked):
D. S. Steinberg, *Vibration Analysis for Electronic Equipment*, 3rd ed., Wiley 2000, sample problem
"Response of a PCB to a half-sine shock pulse", p. 262 (eqs. 11.23-11.25), as transcribed in the
public notebook github.com/natecostello/python-test-repo, steinberg.ipynb: a 6 x 8 in board,
0.093 in thick, with a 40-pin side-brazed DIP (c = 1.26, L = 2.0 in) at its centre (r = 1)
parallel to the 8 in edge (B = 8.0 in), 100 G input, shock amplification A = 1.6; the book finds
the desired board frequency f_d = 157 Hz. Steinberg's shock limit, eq. 11.23, is his vibration
limit Z = 0.00022 B / (c h r sqrt(L)) without the factors 3 (fatigue) and 2 (stress concentration),
i.e. 6 Z; the same six appears in T. Irvine's Vibrationdata tool (circuit_board_fatigue.m: "Peak
Limits for 1 Shock" = 6 Z). No published fatigue-life example with numbers was found: the lives
below are checked against values computed by hand from the formulas, as stated in each test.
"""

import numpy as np
import pytest
from scipy.integrate import trapezoid

from pcbdyn.vibration import steinberg

INCH = 0.0254


def test_steinberg_sample_problem_p262_desired_frequency():
    z = steinberg.allowable_displacement(8.0 * INCH, 2.0 * INCH, 0.093 * INCH, 1.26, 1.0)
    # by hand: 0.00022 * 8 / (1.26 * 0.093 * 1 * sqrt(2)) = 0.00176 / 0.165720 = 0.0106205 in
    assert z / INCH == pytest.approx(0.0106205, rel=1e-5)
    z_shock = 6.0 * z / INCH  # eq. 11.23: 0.00132 B / (c h r sqrt(L)) = 0.063723 in
    assert z_shock == pytest.approx(0.00132 * 8.0 / (1.26 * 0.093 * np.sqrt(2.0)), rel=1e-12)
    f_d = np.sqrt(9.8 * 100.0 * 1.6 / z_shock)  # eq. 11.25 (eq. 11.24 Z = 9.8 G A / f^2, inches)
    assert f_d == pytest.approx(157.0, abs=0.5)  # the book's answer


def test_position_factor_raises_the_allowable_as_steinberg_tabulates():
    z1 = steinberg.allowable_displacement(0.2, 0.02, 1.6e-3, 1.0, 1.0)
    assert steinberg.allowable_displacement(0.2, 0.02, 1.6e-3, 1.0, 0.707) == pytest.approx(z1 / 0.707)
    assert steinberg.allowable_displacement(0.2, 0.02, 1.6e-3, 1.0, 0.5) == pytest.approx(2.0 * z1)


def test_three_band_life_at_the_allowable_is_steinbergs_2e7_cycles():
    z_allow, rate = 1e-3, 200.0
    life = steinberg.random_life(z_allow / 3.0, z_allow, rate)
    assert life * rate == pytest.approx(2.0e7, rel=1e-12)
    # the S-N anchor by hand: 2e7 (0.683 / 3^6.4 + 0.271 (2/3)^6.4 + 0.0433)
    #   = 2e7 (0.683 * 8.8437e-4 + 0.271 * 0.074655 + 0.0433) = 2e7 * 0.064135 = 1.2827e6 cycles
    assert steinberg.reference_cycles() == pytest.approx(1.2827e6, rel=1e-4)


def test_life_of_the_sample_problem_part_computed_by_hand():
    """Hand computation (not from the book): the DIP of p. 262 (Z = 0.0106205 in) at 0.004 in RMS,
    150 cycles/s. Three-band with the 2e7-cycle anchor is N = 2e7 (Z / 3 z)^6.4:
    Z / 3 z = 0.0106205 / 0.012 = 0.885040; ln = -0.122129; x 6.4 = -0.781626; exp = 0.457682;
    N = 9.15364e6 cycles; / 150 Hz = 61024 s = 16.95 h."""
    z_allow = steinberg.allowable_displacement(8.0 * INCH, 2.0 * INCH, 0.093 * INCH, 1.26, 1.0)
    hours = steinberg.random_life(0.004 * INCH, z_allow, 150.0) / 3600.0
    assert hours == pytest.approx(16.95, abs=0.01)
    assert steinberg.random_life(0.0, z_allow, 150.0) == float("inf")


def test_sine_sweep_damage_computed_by_hand():
    """A 10-2000 Hz sweep at 1 octave/min at a constant amplitude equal to the allowable:
    cycles = 60 (2000 - 10) / ln 2 = 172,257; D = 172,257 / 1.2827e6 = 0.1343."""
    f = np.geomspace(10.0, 2000.0, 2001)
    d = steinberg.sweep_damage(f, np.full(f.size, 1e-3), 1e-3, 1.0)
    assert d == pytest.approx(0.1343, abs=2e-4)
    # twice the amplitude: 2^6.4 = 84.45 times the damage
    assert steinberg.sweep_damage(f, np.full(f.size, 2e-3), 1e-3, 1.0) == pytest.approx(d * 2**6.4, rel=1e-9)


def test_zero_crossing_rate_of_a_narrow_band_is_its_frequency():
    f = np.linspace(99.0, 101.0, 2001)
    m0, m2 = trapezoid(np.ones_like(f), f), trapezoid(f**2, f)
    assert steinberg.zero_crossing_rate(m0, m2) == pytest.approx(100.0, rel=1e-4)


@pytest.mark.parametrize("f_board, ok, rule", [(250.0, True, "forward"), (150.0, False, "within an octave"),
                                               (40.0, True, "reverse")])
def test_octave_rule(f_board, ok, rule):
    res = steinberg.octave_rule(f_board, 100.0)
    assert res["ok"] is ok and res["rule"].startswith(rule) and res["ratio"] == pytest.approx(f_board / 100.0)
