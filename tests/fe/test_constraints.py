"""Constraints by elimination: fixed DOFs, rigid links and coupled DOFs give the closed-form answers."""

import numpy as np
import pytest

from pcbdyn.fe import MassProperty, Model, ModelError, SpringProperty
from pcbdyn.fe.modal import solve_modes


def test_rigid_link_with_lever_arm():
    """A mass at distance d from a pivot on a torsion spring kr: omega^2 = kr / (m d^2)."""
    d, m, kr = 0.3, 2.0, 50.0
    model = Model([[0, 0, 0], [d, 0, 0]])
    model.add("pivot", "spring", [[0]], SpringProperty(k=(0, 0, 0, 0, 0, kr)))
    model.add("m", "mass", [[1]], MassProperty(m))
    model.fix(0, ["ux", "uy", "uz", "rx", "ry"])
    model.rigid_link(0, [1])
    modes = solve_modes(model, n_modes=1)
    assert modes.frequencies[0] == pytest.approx(np.sqrt(kr / (m * d**2)) / (2 * np.pi), rel=1e-10)
    # the slave follows the lever: uy_slave = d * rz_master
    phi = modes.shapes[:, 0]
    assert phi[6 + 1] == pytest.approx(d * phi[5], rel=1e-12)


def test_partial_rigid_link_and_coupling():
    """Two masses tied in x only share one spring: omega^2 = k / (m1 + m2); a coupled DOF likewise."""
    k, m1, m2 = 1e4, 1.0, 3.0
    for tie in ("link", "couple"):
        model = Model([[0, 0, 0], [0.1, 0.2, 0]])
        model.add("k", "spring", [[0]], SpringProperty(k=(k, 0, 0, 0, 0, 0)))
        model.add("m", "mass", [[0], [1]], MassProperty(m1))
        model.add("m2", "mass", [[1]], MassProperty(m2 - m1))
        model.fix(0, ["uy", "uz", "rx", "ry", "rz"])
        model.fix(1, ["uy", "uz", "rx", "ry", "rz"])
        if tie == "link":
            model.rigid_link(0, [1], dofs=(0,))
        else:
            model.couple(0, 6)
        f = solve_modes(model, n_modes=1).frequencies[0]
        assert f == pytest.approx(np.sqrt(k / (m1 + m2)) / (2 * np.pi), rel=1e-10)


def test_constraint_cycle_is_reported():
    model = Model([[0, 0, 0], [1, 0, 0]])
    model.add("k", "spring", [[0], [1]], SpringProperty(k=(1, 1, 1, 1, 1, 1)))
    model.add("m", "mass", [[0], [1]], MassProperty(1.0, (1, 1, 1)))
    model.couple(0, 6)
    model.couple(6, 0)
    with pytest.raises(ModelError, match="cycle"):
        solve_modes(model, n_modes=1)
