"""`pcbdyn build`: table, CSV, VTU, PNG and JSON outputs, checked against a simply supported plate."""

import json

import numpy as np
import pytest
from board_helpers import write_board
from click.testing import CliRunner

from pcbdyn.cli import main
from data_files import board_text

PLATE = board_text("hinged_plate.toml")


def navier(m, n, a=0.1, b=0.08, t=1.6e-3, E=22e9, nu=0.15, rho=1850.0):
    D = E * t**3 / (12 * (1 - nu**2))
    return 0.5 * np.pi * ((m / a) ** 2 + (n / b) ** 2) * np.sqrt(D / (rho * t))


def test_build_writes_every_output_and_matches_the_plate_formula(tmp_path):
    board = write_board(tmp_path, PLATE)
    out, js = tmp_path / "out", tmp_path / "r" / "modes.json"
    res = CliRunner().invoke(main, ["build", str(board), "--out", str(out), "--json", str(js)])
    assert res.exit_code == 0, res.output
    data = json.loads(js.read_text())
    f = [m["frequency_hz"] for m in data["modes"]]
    ref = sorted(navier(m, n) for m in range(1, 4) for n in range(1, 4))[:4]
    np.testing.assert_allclose(f, ref, rtol=0.01)
    assert data["mass_kg"] == pytest.approx(0.1 * 0.08 * 1.6e-3 * 1850, rel=1e-9)
    assert data["dofs"] > 0 and [m["n"] for m in data["modes"]] == [1, 2, 3, 4]
    # mode 1 is the (1,1) half-sine: no interior nodal line, most of the mass moving in z
    assert data["modes"][0]["shape"].startswith("(0,0)")
    assert data["modes"][1]["shape"].startswith("(1,0)")  # (2,1): one nodal line across x
    assert data["modes"][0]["eff_mass_z"] == pytest.approx(64 / np.pi**4, rel=0.02)  # (mean sin)^4 / (mean sin^2)^2
    assert "frequency [Hz]" in res.output and "eff. mass z [%]" in res.output
    csv = (out / "modes_base.csv").read_text().splitlines()
    assert csv[0].startswith("mode,frequency_hz") and len(csv) == 5
    import pyvista as pv

    grid = pv.read(str(out / "modes_base.vtu"))
    assert grid.n_cells > 0 and "mode_4" in grid.point_data
    pngs = sorted((out / "png").glob("modes_base_*.png"))
    assert len(pngs) == 4 and all(p.stat().st_size > 1000 for p in pngs)
    assert not list(out.glob(".*"))  # no temporary files left behind


def test_all_configs_and_added_mass_lowers_the_first_mode(tmp_path):
    board = write_board(tmp_path, PLATE)
    js = tmp_path / "modes.json"
    res = CliRunner().invoke(main, ["build", str(board), "--all-configs", "--json", str(js)])
    assert res.exit_code == 0, res.output
    data = json.loads(js.read_text())
    base, loaded = data["configurations"]
    assert loaded["mass_kg"] - base["mass_kg"] == pytest.approx(0.010, rel=1e-9)
    assert loaded["modes"][0]["frequency_hz"] < base["modes"][0]["frequency_hz"]


def test_bad_board_exits_with_the_message(tmp_path):
    board = write_board(tmp_path, PLATE.replace('edge = "y=0"', 'edge = "y=5 mm"'))
    res = CliRunner().invoke(main, ["build", str(board)])
    assert res.exit_code == 2
    assert "board.toml: fixtures[2].edge: 'y=5 mm' is not an edge" in res.output
