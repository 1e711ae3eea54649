"""The stage of :mod:`pcbdyn.diagnosis.conforming`: a structure meshed along the lines of stiffeners
found, and the walk of a line across to its least chi^2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.board import build_model, load_board
from pcbdyn.diagnosis import conforming
from pcbdyn.fe.modal import solve_modes

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card" / "board.toml"
Y, EI = 0.0703, 3.7333  # off the card's node rows at its 6.75 mm mesh


def test_meshed_along_a_line_the_rib_found_is_the_rib_declared(tmp_path):
    """The card meshed along y = 70.3 mm has a row of nodes there across its width, and a stiffener
    candidate along it changes the card as the same rib declared in board.toml ([[stiffeners]], meshed
    on that line as a beam) does: equal frequencies. Embedded in the cells of the card's own mesh
    (no node row there), the same rib gives other frequencies."""
    declared = tmp_path / "board.toml"
    declared.write_text(CARD.read_text() + f'\n[[stiffeners]]\nname = "bar"\npath = [["0 mm", "{1e3 * Y} mm"], '
                        f'["162 mm", "{1e3 * Y} mm"]]\nEI = "{EI} N*m^2"\n')
    f_declared = solve_modes(build_model(load_board(declared), shared_mesh=True).model, n_modes=8).frequencies
    card = load_board(CARD)
    line = np.array([[0.0, Y], [0.162, Y]])
    got = {}
    for name, board in (("along", card.following([line])), ("own", card)):
        bm = build_model(board, shared_mesh=True)
        on_row = np.isclose(bm.model.nodes[:, 1], Y, atol=1e-9)
        got[name] = (on_row.sum(), bm)
        rib = dg.kind("stiffener").candidate(dg.from_structure(bm), "t", *line)
        got[name] += (solve_modes(dg.add_effect(bm.model, rib, EI), n_modes=8).frequencies,)
    assert got["along"][0] >= 0.162 / card.mesh_size and got["own"][0] == 0
    assert got["along"][2] == pytest.approx(f_declared, rel=1e-9)
    assert np.max(np.abs(got["own"][2] / f_declared - 1.0)) > 1e-3


def test_vertex_of_the_parabola_through_three_places():
    """chi^2 = 5 (x - x0)^2 + 40 sampled at -d, 0, d: the vertex is x0 where it lies between the outer
    places, the nearer outer place beyond them, and the least sample where the parabola opens down
    or a place could not be meshed (infinite chi^2)."""
    d = 1.7e-3
    xs = [-d, 0.0, d]
    for x0 in (-0.6e-3, 0.0, 0.9e-3):
        assert conforming.vertex(xs, [5.0 * (x - x0) ** 2 / d**2 + 40.0 for x in xs]) == pytest.approx(x0, abs=1e-12)
    assert conforming.vertex(xs, [5.0 * (x - 3 * d) ** 2 / d**2 for x in xs]) == pytest.approx(d)
    assert conforming.vertex(xs, [1.0, 3.0, 2.0]) == -d
    assert conforming.vertex(xs, [np.inf, 3.0, 2.0]) == d


def test_moved_stiffener_keeps_its_kind_and_is_renamed_for_its_line():
    bm = build_model(load_board(CARD), shared_mesh=True)
    layout = dg.from_structure(bm)
    row = dg.kind("stiffener").candidate(layout, "y=70mm", np.array([0.0, 0.070]), np.array([0.162, 0.070]))
    col = dg.kind("stiffener").candidate(layout, "x=40mm", np.array([0.040, 0.0]), np.array([0.040, 0.178]))
    out = conforming.moved([row, col], 0, -0.5e-3)
    out = conforming.moved(out, 1, 1.25e-3)
    assert out[0].name == "stiffener@y=69.5mm" and out[1].name == "stiffener@x=41.25mm"
    assert np.allclose(out[0].geometry["path"], [[0.0, 0.0695], [0.162, 0.0695]])
    assert np.allclose(out[1].geometry["path"], [[0.04125, 0.0], [0.04125, 0.178]])
    assert out[0].at == pytest.approx((0.081, 0.0695)) and row.name == "stiffener@y=70mm"
