"""Mass bookkeeping for every part model, and the wedge-lock limits (thesis section 7.4)."""

import numpy as np
import pytest
from board_helpers import DATA, EXAMPLES, write_board

from pcbdyn.board import build_model, load_board
from pcbdyn.fe.modal import solve_modes


def expected_mass(board, config=None):
    m = board.outline.area() * board.plate.mass_per_area()
    m += sum(c.mass for c in board.components) + sum(p.mass for p in board.masses)
    if config:
        m += sum(p.mass for p in board.configuration(config).masses)
    return m


@pytest.mark.parametrize("config", [None, "heavy"])
def test_model_mass_is_board_plus_parts_plus_masses(config):
    board = load_board(DATA / "all_models.toml")
    assert {c.model for c in board.components} == {"lumped", "spread", "smeared_local", "equivalent_thickness"}
    bm = build_model(board, config)
    assert bm.mass() == pytest.approx(expected_mass(board, config), rel=1e-9)


@pytest.mark.parametrize("model", ["lumped", "spread", "smeared_local", "equivalent_thickness"])
def test_every_part_model_keeps_the_part_mass(tmp_path, model):
    text = (EXAMPLES / "six_part_card" / "board.toml").read_text()
    text = text.replace('package = "PGA"', f'package = "PGA"\nmodel = "{model}"').split("[[parameters]]")[0]
    board = load_board(write_board(tmp_path, text))
    assert [c.model for c in board.components if c.package == "PGA"] == [model, model]
    assert build_model(board).mass() == pytest.approx(expected_mass(board), rel=1e-9)


def test_global_smearing_keeps_the_mass(tmp_path):
    text = (DATA / "all_models.toml").read_text().replace('mesh_size = "7.5 mm"', 'mesh_size = "7.5 mm"\nsmear = "global"')
    text = text.split("[[parameters]]")[0]
    board = load_board(write_board(tmp_path, text))
    bm = build_model(board)
    assert not any(name.startswith("components.") for name in bm.model.sets)
    assert bm.mass() == pytest.approx(expected_mass(board), rel=1e-9)


def test_laminate_board_mass():
    board = load_board(EXAMPLES / "plain_plate" / "board.toml")
    assert build_model(board).mass() == pytest.approx(expected_mass(board), rel=1e-9)


@pytest.mark.parametrize("t_eq", [2.0e-3, 3.5e-3, 7.0e-3])
def test_equivalent_thickness_keeps_each_part_mass_whatever_t_eq(t_eq):
    """Thesis eq. 7.7: the region density follows the thickness so board + part mass is fixed."""
    board = load_board(EXAMPLES / "six_part_card" / "board.toml")
    bm = build_model(board).with_parameters({"t_PGA": t_eq, "t_JLCC": t_eq, "t_CQFP": t_eq})
    assert bm.mass() == pytest.approx(expected_mass(board), rel=1e-9)
    for c in board.components:
        prop = bm.model.sets[f"components.{c.ref}"].prop
        assert prop.t == t_eq
        region = prop.mass_per_area() * c.area
        assert region == pytest.approx(c.mass + board.plate.mass_per_area() * c.area, rel=1e-12)


def _limit(tmp_path, k):
    text = (EXAMPLES / "wedge_locked" / "board.toml").read_text().replace('k_rot = "1e4 N*m/rad/m"', f'k_rot = "{k}"')
    text = text.split("[[parameters]]")[0]
    return solve_modes(build_model(load_board(write_board(tmp_path, text, f"{k[:3]}.toml"))).model, n_modes=5).frequencies


def test_wedge_lock_limits_are_hinged_and_clamped(tmp_path):
    soft = _limit(tmp_path, "1e-2 N*m/rad/m")
    stiff = _limit(tmp_path, "1e7 N*m/rad/m")
    hinged = _limit(tmp_path, "hinged")
    clamped = _limit(tmp_path, "clamped")
    assert np.max(np.abs(soft / hinged - 1)) < 0.005
    assert np.max(np.abs(stiff / clamped - 1)) < 0.005
    assert np.all(clamped > 1.5 * hinged[0])  # and the two limits are far apart
