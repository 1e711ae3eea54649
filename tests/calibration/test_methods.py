"""Calibration methods and options on one board whose test is simulated on its own mesh with the
families at known values (no part scatter): QMS with the stated noise (its rows weighted by redrawing
that noise on the data), and --with board.E fitted beside the families."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from pcbdyn.cli import main

from sim_boards import LAYOUTS, TRUE_MM, board_text, simulated_test

MESH = 10.0


def case(tmp_path, E="24 GPa"):
    refs = {f"U{i + 1}": TRUE_MM[f] for i, (f, _, _) in enumerate(LAYOUTS["b1"][2])}
    truth = tmp_path / "truth.toml"
    truth.write_text(board_text("b1", MESH, refs).replace('E = "24 GPa"', f'E = "{E}"'))
    board = tmp_path / "b1.toml"
    board.write_text(board_text("b1", MESH))
    return board, simulated_test(truth, tmp_path / "test.uff", "b1", n_modes=7)


def calibrate(args, tmp_path):
    js = tmp_path / "c.json"
    r = CliRunner().invoke(main, ["calibrate", *map(str, args), "--library", str(tmp_path / "lib"), "--json", str(js)])
    assert r.exit_code == 0, r.output
    return json.loads(js.read_text())


def test_qms_with_stated_noise(tmp_path):
    board, test = case(tmp_path)
    data = calibrate([board, test, "--method", "qms", "--noise", "f=0.2,shape=2", "--no-mesh-error"], tmp_path)
    assert "rows weighted by redraws" in data["noise"] and data["method"] == "qms"
    for fam, d in data["families"].items():
        v, sd = d["equivalent_thickness_m"], d["std_m"]
        print(f"{fam}: {v * 1e3:.4f} +- {sd * 1e3:.4f} mm, true {TRUE_MM[fam]} mm")
        assert abs(v - TRUE_MM[fam] * 1e-3) < 3 * sd and sd < 0.02 * v


def test_with_board_E(tmp_path):
    """The board's E is 24 GPa in the file and 26 GPa in the truth: fitted beside the families, both come
    back within 3 standard deviations (and E within 2 %)."""
    board, test = case(tmp_path, E="26 GPa")
    data = calibrate([board, test, "--with", "board.E", "--noise", "f=0.2,shape=2", "--no-mesh-error"], tmp_path)
    E = data["with"]["board.E"]
    print(f"E {E['updated'] / 1e9:.3f} +- {E['std'] / 1e9:.3f} GPa;",
          {f: round(d["equivalent_thickness_m"] * 1e3, 3) for f, d in data["families"].items()})
    assert E["initial"] == pytest.approx(24e9) and abs(E["updated"] - 26e9) < min(3 * E["std"], 0.02 * 26e9)
    for fam, d in data["families"].items():
        assert abs(d["equivalent_thickness_m"] - TRUE_MM[fam] * 1e-3) < 3 * d["std_m"]
