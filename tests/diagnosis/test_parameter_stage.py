"""Where the effect search starts (:func:`pcbdyn.diagnosis.parameter_stage.declared_origin`): also from the
declared values when the declared parameters fitted alone stop on a bound, as an effect the model
lacks can pull them there (dev seed 21: a bracket beside a standoff took the standoffs' stiffness to its
bound, and the search from there found a stiffener and an edge stiffness)."""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.parameter_stage import declared_origin
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.select import estimate
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import MeasuredModes

from diagnosis_plates import guided_card

E0, N_MODES = 26e9, 8


@pytest.fixture(scope="module")
def residual():
    """The guided card's modulus as the one declared parameter, its test the card with a 20 g mass the
    model lacks (frequencies alone, 0.2 %)."""
    m = guided_card(E=E0)
    layout = dg.from_model(m)
    near = min(dg.generate(layout, kinds=["point_mass"]),
               key=lambda c: np.linalg.norm(np.subtract(c.at[:2], (0.07, 0.09))))
    f = solve_modes(dg.add_effect(m, near, 0.020), n_modes=N_MODES).frequencies
    n = m.n_dof
    dK = assemble(guided_card(E=1.0), sets=["plate"])[0]
    return ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(N_MODES, 0.002))],
                         lambda p: [guided_card(E=p[0])], lambda p, models: [[(dK, sp.csr_matrix((n, n)))]],
                         n_params=1)


@pytest.mark.parametrize("lower, searched", [(0.99, True), (0.1, False)], ids=["on its bound", "within"])
def test_a_parameter_on_its_bound_starts_the_search_from_the_declared_values(residual, lower, searched):
    """The mass lowers every frequency, and the modulus fitted alone follows it down: to its bound where
    that is 1 % below the declared value (the search then also starts from the declared values, the
    state there unstepped), to a value within bounds ten times wider, where the frequencies fit better
    than at the declared value and the search starts from the fit alone."""
    bounds = (np.array([lower * E0]), np.array([10 * E0]))
    models = SimpleNamespace(names=["E"], bounds=bounds)
    base = estimate(residual, np.array([E0]), [], [], 10, bounds)
    assert bool(base.p[0] == pytest.approx(lower * E0, rel=1e-6)) is searched
    at = declared_origin(residual, base, np.array([E0]), models, lambda msg: None)
    assert (at is not None) is searched
    if searched:
        assert at.p == pytest.approx([E0], rel=1e-12)
        assert at.chi2 > base.chi2
