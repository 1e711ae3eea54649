"""Every bundled example has measurement points (points.csv beside its board.toml), in the
format of the six-part card's, and every point lies on its board: inside the outline, off the
holes, and close to the mid-plane."""

import numpy as np
import pytest
from board_helpers import EXAMPLES

from pcbdyn.board import load_board
from pcbdyn.commands.common import PROBE_TOL
from pcbdyn.testdata import read_points_csv

BOARDS = sorted(EXAMPLES.glob("*/board.toml"))


def test_the_examples_are_found():
    assert {b.parent.name for b in BOARDS} >= {"six_part_card", "wedge_locked", "plain_plate"}


@pytest.mark.parametrize("board_toml", BOARDS, ids=lambda p: p.parent.name)
def test_each_example_has_points_on_its_board(board_toml):
    csv = board_toml.parent / "points.csv"
    assert csv.is_file(), f"{board_toml.parent.name} has no points.csv"
    header = next(line for line in csv.read_text().splitlines() if not line.startswith("#"))
    assert header == "point,x [mm],y [mm],dir"
    board = load_board(board_toml)
    points, dofs = read_points_csv(csv)
    assert len(points) >= 20 and np.all(np.abs(dofs.directions[:, 2]) == 1.0)
    board.check_points(points, csv.name)  # raises naming any point off the board
    assert board.outline.contains(points.xyz[:, :2]).all()
    assert np.all(np.abs(points.xyz[:, 2]) <= PROBE_TOL)
