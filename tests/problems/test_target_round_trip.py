"""Every parameter-target kind round-trips through ``pcbdyn update``: the board.updated.toml it writes
loads, rebuilds the updated model exactly (the same stiffness and mass matrices as the model with the
updated value) and keeps every comment of the user's file (issue 17)."""

import json
import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.board import load_board
from pcbdyn.cli import main
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import solve_modes

from data_files import board_file

BOARD = board_file("every_target.toml")
PARAMS = {p.name: p for p in load_board(BOARD).parameters}


def comments(text: str) -> list:
    return [line[line.index("#"):] for line in text.splitlines() if "#" in line and '"#' not in line]


@pytest.mark.parametrize("name", list(PARAMS))
def test_update_writes_a_board_that_rebuilds_the_updated_model(tmp_path, name):
    path = tmp_path / "board.toml"
    shutil.copy(BOARD, path)
    board = load_board(path)
    spec = PARAMS[name]
    true = spec.value * (2.0 if spec.log else 1.15)
    pm = board.build()
    f = solve_modes(pm.with_parameters({name: true}).model, n_modes=6).frequencies
    csv = tmp_path / "f.csv"
    csv.write_text("configuration,mode,frequency_hz\n" + "".join(f"base,{k + 1},{float(v)!r}\n" for k, v in enumerate(f)))
    js = tmp_path / "u.json"
    r = CliRunner().invoke(main, ["update", str(path), "--frequencies", str(csv), "--params", name, "--max-iter", "3",
                                  "--json", str(js), "--force", "--no-mesh-check"])  # the board is written whatever 3 steps reach
    assert r.exit_code == 0, r.output
    updated_value = json.loads(js.read_text())["parameters"][name]["updated"]
    assert updated_value != pytest.approx(spec.value, rel=1e-3), "the update did not move the parameter"
    written = tmp_path / "board.updated.toml"
    again = load_board(written)
    for t in spec.targets:
        assert again.quantity(t) == pytest.approx(updated_value, rel=1e-12)
    K1, M1 = assemble(again.build().model)
    K0, M0 = assemble(pm.with_parameters({name: updated_value}).model)
    for A, B in ((K1, K0), (M1, M0)):
        assert A.shape == B.shape and abs(A - B).max() <= 1e-10 * abs(B).max()
    kept = comments(written.read_text())
    assert all(c in kept for c in comments(path.read_text()))


def test_a_target_the_board_does_not_have_is_refused_with_the_patterns(tmp_path):
    text = BOARD.read_text().replace('target = "regions.patch.stiffness_factor"', 'target = "regions.patch.thickness"')
    path = tmp_path / "board.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=r"board.toml: parameters\[14\].target: 'regions.patch.thickness' is not a "
                                         r"target of this structure; .*targets are .*regions.<name>.stiffness_factor"):
        load_board(path)


def test_written_values_follow_the_units_the_user_wrote(tmp_path):
    path = tmp_path / "board.toml"
    shutil.copy(BOARD, path)
    board = load_board(path)
    out = board.write_updated({"E": 2.5e10, "k_guide": 3000.0, "f_patch": 1.5, "shear": 2.0}, tmp_path / "u.toml")
    text = out.read_text()
    assert 'E = "25.0 GPa"' in text and 'k_rot = "3000.0 N*m/rad/m"' in text
    assert "stiffness_factor = 1.5" in text and "transverse_shear = 2.0" in text
    assert np.isclose(load_board(out).transverse_shear, 2.0)
