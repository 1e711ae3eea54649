"""Parameter derivatives from the touched element sets agree with re-assembling the whole model."""

import numpy as np
import pytest
from board_helpers import DATA

from pcbdyn.board import build_model, load_board
from pcbdyn.fe.assembly import assemble


@pytest.fixture(scope="module")
def bm():
    return build_model(load_board(DATA / "all_models.toml"))


def _full(bm, name, value):
    return assemble(bm.with_parameters({name: value}).model)


NAMES = ["t_U1", "m_U2", "E_U3", "rho_U3", "m_U4", "E_board", "rho_board", "t_board", "k_left", "k_s1", "m_tx", "shear"]


@pytest.mark.parametrize("name", NAMES)
def test_derivative_matches_full_reassembly(bm, name):
    p = bm.parameters[name]
    dK, dM = p.derivatives(bm)
    h = 1e-3 * p.value  # a different, forward step on the complete model
    K1, M1 = _full(bm, name, p.value + h)
    K0, M0 = assemble(bm.model)
    K2, M2 = _full(bm, name, p.value + 2 * h)
    # second-order forward difference: (-3 A0 + 4 A1 - A2) / 2h
    fdK = (-3 * K0 + 4 * K1 - K2) / (2 * h)
    fdM = (-3 * M0 + 4 * M1 - M2) / (2 * h)
    for d, fd, A in ((dK, fdK, K0), (dM, fdM, M0)):
        scale = max(abs(fd).max(), abs(d).max())
        roundoff = 1e-13 * abs(A).max() / h  # what the full-model difference cannot resolve
        assert abs(d - fd).max() <= 1e-6 * scale + roundoff
    assert abs(dK).max() + abs(dM).max() > 0, "a parameter must change the model"


def test_each_parameter_touches_only_its_sets(bm):
    sets = {n: set(p.sets) for n, p in bm.parameters.items()}
    assert sets["t_U1"] == {"components.U1"}
    assert sets["m_U2"] == {"components.U2"}
    assert sets["E_U3"] == sets["rho_U3"] == {"components.U3"}
    assert sets["m_U4"] == {"components.U4.mass"}
    assert sets["k_left"] == {"fixtures.left"}
    assert sets["k_s1"] == {"fixtures.s1"}
    assert sets["m_tx"] == {"masses.tx"}
    # the base material reaches every region that is made from it, not the locally smeared one
    assert sets["E_board"] == {"board", "components.U1", "components.U2", "components.U4"}


def test_linear_parameters_scale_their_sets(bm):
    """K of a guide is linear in k_rot and K of a standoff in k: K = p dK/dp."""
    for name, which in (("k_left", 0), ("k_s1", 0)):
        p = bm.parameters[name]
        d = p.derivatives(bm)[which]
        A = assemble(bm.model, sets=list(p.sets))[which]
        assert abs(p.value * d - A).max() <= 1e-9 * abs(A).max()


def test_shared_parameter_sets_every_target():
    bm = build_model(load_board(DATA.parent.parent.parent / "examples" / "wedge_locked" / "board.toml"))
    new = bm.with_parameters({"k_guides": 5e4})
    assert new.quantities["fixtures.bottom_guide.k_rot"] == new.quantities["fixtures.top_guide.k_rot"] == 5e4
    assert new.model.sets["fixtures.top_guide"].prop.k[3] == 5e4
    assert bm.model.sets["fixtures.top_guide"].prop.k[3] == 1e4  # the original is untouched


def test_transverse_shear_tends_to_the_kirchhoff_plate():
    """``board.transverse_shear`` scales every shell's transverse shear stiffness (board and parts):
    stiffer shear never lowers a frequency (Rayleigh), and the free six-part card tends to a
    Kirchhoff plate, whose twisting modes near the free edges lie about t / L above the Mindlin
    shell's (2.8 mm on 162 mm: between 0.3 and 2 %)."""
    from pathlib import Path

    from pcbdyn.fe.modal import solve_modes

    card = build_model(load_board(Path(__file__).resolve().parents[2] / "examples" / "six_part_card" / "board.toml"))
    f = [solve_modes(card.with_quantities({"board.transverse_shear": s}).model, n_modes=6).frequencies
         for s in (1.0, 100.0, 1000.0)]
    assert all(set(card.sets_depending_on(["board.transverse_shear"])) >= {"board", f"components.{c}"}
               for c in ("U1", "U2", "U3"))
    assert np.all(f[1] > f[0]) and np.all(f[2] >= f[1])
    assert 0.3 < 100 * np.max(f[2] / f[0] - 1) < 2.0
    assert np.max(f[2] / f[1] - 1) < 0.1 * np.max(f[2] / f[0] - 1)
