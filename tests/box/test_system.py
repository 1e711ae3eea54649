"""Cards in their housing (box.toml [[cards]]): one model of the box and the boards it holds."""

import numpy as np
import pytest
from system_helpers import ALUMINIUM, STEEL, housing

from pcbdyn.board import load_board
from pcbdyn.box import BoxError, load_box
from pcbdyn.fe.modal import solve_modes


def _modes(structure, n=4):
    return solve_modes(structure.build().model, n).frequencies


def test_a_card_in_stiff_walls_has_the_modes_of_the_card_alone(tmp_path):
    """30 mm steel walls hold the guides as the fixed frame does: the first four modes within 0.5 %."""
    box = load_box(housing(tmp_path, 30.0, STEEL))
    alone = _modes(load_board(tmp_path / "card.toml"))
    housed = _modes(box)
    assert np.allclose(housed, alone, rtol=5e-3), (housed, alone)
    assert not np.allclose(housed, alone, rtol=1e-9)  # the walls do give a little


def test_thin_walls_lower_the_first_mode_and_the_mass_is_the_sum_of_the_parts(tmp_path):
    box = load_box(housing(tmp_path, 1.5, ALUMINIUM))
    card = load_board(tmp_path / "card.toml")
    system = box.build()
    f1 = solve_modes(system.model, 1).frequencies[0]
    assert f1 < 0.97 * _modes(card, 1)[0]
    empty = load_box(housing(tmp_path, 1.5, ALUMINIUM, cards=False, name="empty.toml"))
    parts = empty.build().mass() + card.build().mass()
    assert system.mass() == pytest.approx(parts, rel=1e-9)


def test_a_fixture_that_touches_nothing_is_named_with_its_gap(tmp_path):
    path = housing(tmp_path, 2.0, ALUMINIUM)
    path.write_text(path.read_text().replace('origin = ["0 mm", "10 mm", "60 mm"]', 'origin = ["30 mm", "10 mm", "60 mm"]'))
    with pytest.raises(BoxError, match=r"cards\[0\]: fixture 'left_guide' \(wedge_lock\) of card 'card1' .* touches "
                                       r"nothing: the nearest, plate 'left', is 29 mm away"):
        load_box(path)
