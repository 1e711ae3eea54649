"""The stage of :mod:`pcbdyn.diagnosis.conforming`: a structure meshed along the lines of stiffeners
found, and a rib moved across its line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.board import build_model, load_board
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


def test_moved_stiffener_keeps_its_kind_and_is_renamed_for_its_line():
    bm = build_model(load_board(CARD), shared_mesh=True)
    layout = dg.from_structure(bm)
    row = dg.kind("stiffener").candidate(layout, "y=70mm", np.array([0.0, 0.070]), np.array([0.162, 0.070]))
    col = dg.kind("stiffener").candidate(layout, "x=40mm", np.array([0.040, 0.0]), np.array([0.040, 0.178]))
    rib = dg.kind("stiffener")
    out = [rib.parallel(layout, row, [-0.5e-3])[0], rib.parallel(layout, col, [1.25e-3])[0]]
    assert out[0].name == "stiffener@(0,69.5)-(162,69.5)mm" and out[1].name == "stiffener@(41.25,0)-(41.25,178)mm"
    assert np.allclose(out[0].geometry["path"], [[0.0, 0.0695], [0.162, 0.0695]])
    assert np.allclose(out[1].geometry["path"], [[0.04125, 0.0], [0.04125, 0.178]])
    assert out[0].at == pytest.approx((0.081, 0.0695)) and row.name == "stiffener@y=70mm"
