"""Effective modal masses (pcbdyn.fe.effective_mass) against the analytical share of a cantilever's
first mode, the completeness of a clamped model's modes, the rigid-body modes of a free plate, and the
centre of mass of a plate carrying a point mass."""

import numpy as np
import pytest

from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.effective_mass import AXES, centre_of_mass, effective_mass, shortfall
from pcbdyn.fe.generate import nodes_where, rectangle
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.model import Model
from pcbdyn.fe.properties import MassProperty, ShellProperty

ALU = ShellProperty(70e9, 0.33, 2700.0, 1e-3)


def cantilever(L, b, nx, ny, grade=1.0):
    """An L x b plate clamped along x = 0; ``grade`` > 1 crowds the elements towards the clamp
    (x = L (i / nx)^grade)."""
    nodes, conn = rectangle(L, b, nx, ny)
    nodes[:, 0] = L * (nodes[:, 0] / L) ** grade
    model = Model(nodes)
    model.add("plate", "quad4", conn, ALU)
    model.fix(nodes_where(nodes, x=0.0))
    return model


def test_cantilever_plate_first_mode_carries_the_beam_share():
    """A uniform cantilever beam's first mode carries 0.6131 of its mass in the bending direction
    (Blevins, Formulas for natural frequency and mode shape, table 8-1: m_eff1 / m = 0.6131, from
    (int phi)^2 / (L int phi^2) of phi = cosh - cos - sigma (sinh - sin), beta L = 1.8751); a narrow
    cantilever plate (b / L = 0.1) bends as that beam."""
    model = cantilever(0.1, 0.01, 40, 2)
    K, M = assemble(model)
    modes = solve_modes(model, 3, K=K, M=M)
    em = effective_mass(model.nodes, M, modes.shapes)
    first = dict(zip(AXES, em.fractions[0]))
    assert first["z"] == pytest.approx(0.6131, rel=0.01)
    assert first["x"] < 1e-10 and first["y"] < 1e-10  # bending moves no mass in the plane
    assert em.totals[2] == pytest.approx(2700.0 * 0.1 * 0.01 * 1e-3, rel=1e-12)  # r^T M r: the plate's mass


def test_all_modes_of_a_clamped_plate_carry_its_mass():
    """Over all modes of a clamped model the effective masses add up to its mass (and the effective
    inertias to its moments of inertia about the axes through the centre of mass), less what the
    clamp holds: with the elements crowded at the clamp (first one L / 1728 long) that is < 0.1 %.
    Uniform elements (L / 12) leave a visibly larger share at the clamp."""
    for grade, held in ((3.0, 1e-3), (1.0, 2e-2)):
        model = cantilever(0.1, 0.02, 12, 2, grade)
        K, M = assemble(model)
        modes = solve_modes(model, 10_000, K=K, M=M)  # all of them
        assert modes.frequencies.size == 6 * 13 * 3 - 6 * 3
        total = effective_mass(model.nodes, M, modes.shapes).fractions.sum(axis=0)
        if held < 1e-2:
            assert np.all(np.abs(total - 1.0) < held), dict(zip(AXES, total))
        else:
            assert np.all(1.0 - total > 1e-2), dict(zip(AXES, total))
        assert np.all(total < 1.0 + 1e-9)


def test_free_plate_elastic_modes_carry_nothing_and_rigid_modes_everything():
    """The elastic modes of a free structure are mass-orthogonal to every rigid motion (zero effective
    mass); its six rigid-body modes span the translations and the rotations about the centre of mass,
    so they carry 100 % in each direction."""
    nodes, conn = rectangle(0.12, 0.08, 6, 4)
    model = Model(nodes, free=True)
    model.add("plate", "quad4", conn, ALU)
    model.add("mass", "mass", [[7]], MassProperty(0.01, (1e-6, 2e-6, 3e-6)))
    K, M = assemble(model)
    modes = solve_modes(model, 5, K=K, M=M)
    assert modes.n_rigid == 6
    assert np.abs(effective_mass(model.nodes, M, modes.shapes).fractions).max() < 1e-12
    assert effective_mass(model.nodes, M, modes.rigid_shapes).fractions.sum(axis=0) == pytest.approx(np.ones(6),
                                                                                                      abs=1e-9)


def test_centre_of_mass_of_a_plate_with_a_point_mass():
    """m c = sum of first moments: a 12 x 8 cm plate (2.592 g) with 10 g at (0.1, 0.06, 0.0)."""
    nodes, conn = rectangle(0.12, 0.08, 6, 4)
    model = Model(nodes)
    model.add("plate", "quad4", conn, ALU)
    node = int(nodes_where(nodes, x=0.1, y=0.06)[0])
    model.add("mass", "mass", [[node]], MassProperty(0.01))
    _, M = assemble(model)
    m_plate = 2700.0 * 0.12 * 0.08 * 1e-3
    expected = (m_plate * np.array([0.06, 0.04, 0.0]) + 0.01 * np.array([0.1, 0.06, 0.0])) / (m_plate + 0.01)
    assert centre_of_mass(model.nodes, M) == pytest.approx(expected, abs=1e-12)


def test_shortfall_names_the_share_below_ninety_percent():
    """The note of an analysis whose modes carry too little of the mass along the excited axis: the
    cantilever's first mode carries 61 % in z (noted), its first five over 90 % (silent), nothing in x."""
    model = cantilever(0.1, 0.01, 40, 2)
    K, M = assemble(model)
    modes = solve_modes(model, 12, K=K, M=M)
    em = effective_mass(model.nodes, M, modes.shapes)
    bending = np.flatnonzero(em.fractions[:, 2] > 1e-3)  # the bending modes among the twisting ones
    one = effective_mass(model.nodes, M, modes.shapes[:, :1])
    assert shortfall(one, "z", modes.frequencies[:1]).startswith(
        f"the 1 mode used (up to {modes.frequencies[0]:.0f} Hz) carry 61.1 % of the mass moved along z (< 90 %)")
    assert em.share("z") > 0.9 and bending.size >= 3 and shortfall(em, "z", modes.frequencies) is None
    assert em.share("x") < 1e-10 and "carry 0.0 % of the mass moved along x" in shortfall(em, "x", modes.frequencies)
