"""A simulated test of the example system (examples/housed_cards): the test structure is meshed finer (housing
8 mm, cards 4 mm against 10 and 5), its back plate has E x 0.8 and the shelf's guides twice the stiffness
k_rot; the first 20 modes are read at the 175 points of points.csv (on the plates in x, y and z, on the
cards normal to them) with 2 % shape and 0.2 % frequency noise. The update of the back plate's E and the
shelf guides' k_rot (a card's target, cards.shelf.fixtures.*.k_rot) recovers both within 5 %, and writes
the updated box.toml with the shelf's board.toml updated beside it, comments kept."""

import json
import shutil

import numpy as np
import pytest
import tomlkit
from click.testing import CliRunner
from system_helpers import EXAMPLES

from pcbdyn.box import load_box
from pcbdyn.cli import main
from pcbdyn.fe.modal import solve_modes
from pcbdyn.problems import UpdateProblem, run
from pcbdyn.testdata import Noise, read_points_csv, write_uff
from pcbdyn.testdata.simulate import simulate_on_model

NOISE = Noise(0.2, 2.0, 0.0)


def _truth(tmp_path):
    doc = tomlkit.parse((tmp_path / "box.toml").read_text())
    next(p for p in doc["plates"] if p["name"] == "back")["E"] = "56 GPa"
    doc["cards"][1]["board"] = "truth_guides.toml"
    del doc["parameters"]
    (tmp_path / "truth.toml").write_text(tomlkit.dumps(doc))
    guides = (tmp_path / "card_guides.toml").read_text()
    assert guides.count('k_rot = "300 N*m/rad/m"') == 2
    (tmp_path / "truth_guides.toml").write_text(guides.replace("300 N*m/rad/m", "600 N*m/rad/m"))
    return load_box(tmp_path / "truth.toml")


def test_update_recovers_a_plate_modulus_and_a_card_guide_stiffness(tmp_path):
    for f in EXAMPLES.iterdir():
        shutil.copy(f, tmp_path)
    truth = _truth(tmp_path)
    system = truth.build(mesh_size=0.008)
    points, dofs = read_points_csv(tmp_path / "points.csv")
    truth.check_points(points, "points.csv")
    data = simulate_on_model(system.model, solve_modes(system.model, n_modes=20), points, dofs, noise=NOISE, seed=3,
                             tol=0.02)
    test = data.modes
    box = load_box(tmp_path / "box.toml")
    problem = UpdateProblem(box, ["E_back", "k_shelf_guides"])
    sigma = NOISE.frequency_pct / 100 / np.sqrt(3) * test.frequencies
    res, before, after = run(problem, [problem.configuration(None, test, "freq", sigma=sigma)], "bounded", max_iter=8,
                             tol_freq_pct=0.05)
    E, k = res.p / problem.p0
    assert before[0]["max_freq_error_pct"] > 5
    assert E == pytest.approx(0.8, rel=0.05) and k == pytest.approx(2.0, rel=0.05)
    dst = problem.write_updated(res.p, tmp_path / "box.updated.toml")
    card = tmp_path / "card_guides.updated.toml"
    assert "card_guides.updated.toml" in dst.read_text() and "# A 120 mm x 200 mm card held" in card.read_text()
    updated = load_box(dst)
    assert updated.card("shelf").board.fixture("left_guide").k_rot == pytest.approx(600.0 * k / 2.0, rel=1e-9)
    assert updated.plate("back").material.E == pytest.approx(70e9 * E, rel=1e-9)
    # the command, whose frequency rows on a system are in units of their frequency (no noise stated)
    write_uff(tmp_path / "test.uff", data)
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["update", str(tmp_path / "box.toml"), str(tmp_path / "test.uff"), "--params",
                                    "E_back,k_shelf_guides", "--out", str(out), "--json", str(tmp_path / "u.json")])
    assert res.exit_code == 0, res.output
    got = json.loads((tmp_path / "u.json").read_text())["parameters"]
    assert got["E_back"]["updated"] / 70e9 == pytest.approx(0.8, rel=0.05)
    assert got["k_shelf_guides"]["updated"] / 300.0 == pytest.approx(2.0, rel=0.05)
    assert load_box(out / "box.updated.toml").card("shelf").board.path.resolve().parent == tmp_path.resolve()  # beside the card
