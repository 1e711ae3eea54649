"""A configuration none of whose measured modes pairs at some iteration is set aside there, with its
name in the history, instead of ending the whole update (issue 21: a QMS update over three
configurations stopped at "configuration 'c2:4': no measured mode found an analytical partner")."""

import numpy as np
import pytest

from pcbdyn.updating import Configuration, build_equations, update
from pcbdyn.updating.sensitivity import frequencies_hz, pencil_modes

from structures import chain_model

N = 4


def measured(p):
    K, M, _, _ = chain_model(N)(p)
    return frequencies_hz(pencil_modes(K, M)[0])


def test_an_unpairable_configuration_is_set_aside_and_named():
    model = chain_model(N)
    p_true = np.r_[np.ones(N), 1000.0 * np.array([1.0, 1.2, 1.0, 1.0])]
    p0 = np.r_[np.ones(N), np.full(N, 1000.0)]
    good = Configuration(model=model, f_x=measured(p_true), name="good")
    lost = Configuration(model=model, f_x=measured(p_true)[:1], name="lost",
                         pairing=lambda f_a, phi_a, f_x, phi_x: -np.ones(np.size(f_x), int))
    _, blocks, states = build_equations([good, lost], p0)
    assert len(blocks) == 1 and states[1]["set_aside"]
    res = update([good, lost], p0, solver="ls", fixed=range(N), max_iter=10, tol_freq_pct=1e-3)
    assert res.history[0]["set_aside"] == ["lost"]
    assert res.p[N + 1] == pytest.approx(1200.0, rel=1e-3)
    with pytest.raises(ValueError, match="no measured mode of any configuration found an analytical partner"):
        build_equations([lost], p0)
