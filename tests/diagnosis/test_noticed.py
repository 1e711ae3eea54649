"""Nothing reported that the data do not need (issue 37): of two effects fitted together, one real (a
mass the test board carries) and one the data do not ask for (a spring elsewhere, its value fitted to the
noise), :func:`pcbdyn.diagnosis.select.noticed` keeps the mass, whose removal raises chi^2 far beyond an
effect's penalty, and drops the spring."""

from __future__ import annotations

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.select import Selection, estimate, noticed
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import MeasuredModes

from test_select import N_MODES, SIGMA, card  # noqa: F401  (the free card with its candidates)


def test_an_effect_the_data_do_not_need_is_dropped(card):
    m, cands = card
    masses = [c for c in cands if c.kind == "point_mass"]
    springs = [c for c in cands if c.kind == "ground_spring"]
    mass = masses[len(masses) // 3]
    spring = max(springs, key=lambda c: np.hypot(*np.subtract(c.at, mass.at)))
    f = solve_modes(dg.add_effect(m, mass, 0.02), n_modes=N_MODES).frequencies
    rng = np.random.default_rng(4)
    f_test = f * (1.0 + SIGMA * rng.standard_normal(f.size))
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))], lambda p: [m])
    both = [mass, spring]
    fit = estimate(res, np.zeros(0), both, [0.02, 1.0], 8)
    sel = Selection(chosen=[0, 1], values=fit.values, p=fit.p, chi2=[fit.chi2], state=fit.state, cov=fit.cov)
    kept = noticed(res, both, sel)
    assert kept.chosen == [0]
    assert kept.values[0] == pytest.approx(0.02, rel=0.05)
