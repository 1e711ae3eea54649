"""`pcbdyn calibrate` on a test measured at 3 x 3 points (issue 38): the pairing's aliasing warnings are
printed and written, each naming two model modes whose AutoMAC at the test points (computed here from the
model read at the points) is the one the warning states, at or above 0.8."""

import json
import re

import numpy as np
from click.testing import CliRunner

from pcbdyn.board import load_board
from pcbdyn.cli import main
from pcbdyn.correlation import automac
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import model_probe
from pcbdyn.testdata.simulate import simulate_on_model
from pcbdyn.testdata.uff import write_uff

from sim_boards import NOISE, board_text, grid, true_thicknesses

WARNING = re.compile(r"model modes (\d+) and (\d+) look alike at the test points \(AutoMAC ([\d.]+)\)")


def test_calibrate_prints_the_aliasing_of_a_sparse_grid(tmp_path):
    truth = tmp_path / "truth.toml"
    truth.write_text(board_text("b1", thickness_mm=true_thicknesses("b1", 0)))
    pts, dofs = grid("b1", 3, 3)
    model = load_board(truth).build().model
    write_uff(tmp_path / "test.uff", simulate_on_model(model, solve_modes(model, n_modes=6), pts, dofs, noise=NOISE,
                                                       seed=0))
    (tmp_path / "b1.toml").write_text(board_text("b1"))
    r = CliRunner().invoke(main, ["calibrate", str(tmp_path / "b1.toml"), str(tmp_path / "test.uff"), "--families",
                                  "PGA", "--no-mesh-error", "--library", str(tmp_path / "lib"), "--json",
                                  str(tmp_path / "c.json")])
    assert r.exit_code == 0, r.output
    said = json.loads((tmp_path / "c.json").read_text())["warnings"]
    found = [WARNING.search(w) for w in said]
    assert found and all(found) and all(f"warning: {w}" in r.stderr for w in said)
    built = load_board(tmp_path / "b1.toml").build().model
    modes = solve_modes(built, n_modes=12)
    at = model_probe(built, pts.xyz, dofs.directions).P @ modes.shapes
    auto = automac(np.asarray(at))
    for m in found:
        j, k, a = int(m[1]) - 1, int(m[2]) - 1, float(m[3])
        assert a >= 0.8 and abs(auto[j, k] - a) < 0.05  # the start's model; the calibrated one moves a little
