"""``pcbdyn pretest`` (issue 41) from the command line: the JSON contract, the files written (points.csv for
simulate-test and correlate, the structure with the designed [[configurations]], comments kept), and on the
example box triaxial sensors whose simulated test correlates at MAC >= 0.9 with every target mode."""

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.board import load_board
from pcbdyn.box import load_box
from pcbdyn.cli import main
from pcbdyn.correlation import correlate
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import Noise, read_points_csv
from pcbdyn.testdata.simulate import simulate_on_model

ROOT = Path(__file__).resolve().parents[2]
CARD = ROOT / "examples/six_part_card"
BOX = ROOT / "examples/ribbed_box/box.toml"


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_board_pretest_contract_and_configurations(tmp_path):
    out, js = tmp_path / "out", tmp_path / "pretest.json"
    r = run("pretest", CARD / "board.toml", "--candidates", CARD / "points.csv", "--sensors", 12,
            "--masses", "20 g,53.2 g", "--max-places", 6, "--out", out, "--json", js, "--html")
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    assert {"sensors", "automac_max_offdiag", "exciter", "suspension", "configurations", "identifiability"} <= set(d)
    assert len(d["sensors"]) == 12 and all(set(s) == {"id", "x_mm", "y_mm", "direction"} for s in d["sensors"])
    assert d["automac_max_offdiag"] <= 0.25
    assert d["suspension"]["suspension_share_of_first_elastic"] < 0.15
    assert d["exciter"]["meets_required_share"] and d["exciter"]["min_share"] >= d["exciter"]["required_share"] == 0.1
    assert [c["name"] for c in d["configurations"]] == ["pretest1", "pretest2"]
    for c in d["configurations"]:
        (m,) = c["masses"]
        assert set(m) == {"mass_kg", "at_mm"} and any(m["mass_kg"] == pytest.approx(v) for v in (0.02, 0.0532))
    idf = d["identifiability"]
    for key in ("before", "after", "existing"):
        assert set(idf[key]) == {"std_pct", "condition"}
        assert set(idf[key]["std_pct"]) == {"t_PGA", "t_JLCC", "t_CQFP", "E_board"}
    # information only adds: every predicted 1-sigma shrinks with the configurations
    assert all(idf["after"]["std_pct"][n] < idf["before"]["std_pct"][n] for n in idf["before"]["std_pct"])
    # the sensors as a points file simulate-test and correlate read
    pts, dofs = read_points_csv(out / "points.csv")
    assert len(pts) == 12 and np.allclose(dofs.directions, [0, 0, 1])
    np.testing.assert_allclose(pts.xyz[:, :2] * 1e3, [[s["x_mm"], s["y_mm"]] for s in d["sensors"]])
    # the card with the designed configurations: comments kept, the masses where the JSON says
    text = (out / "board.pretest.toml").read_text()
    assert text.startswith("# The thesis' six-part test card") and "designed by pcbdyn pretest" in text
    card = load_board(out / "board.pretest.toml")
    assert card.configuration_names() == ["c2", "c3", "pretest1", "pretest2"]
    for c in d["configurations"]:
        (mass,) = card.configuration(c["name"]).masses
        np.testing.assert_allclose(np.array(mass.at) * 1e3, c["masses"][0]["at_mm"], atol=1e-9)
        assert mass.mass == pytest.approx(c["masses"][0]["mass_kg"])
    assert {"points.csv", "candidates.csv", "pretest_map.png", "board.pretest.toml", "report.html"} <= set(d["files"])


def test_box_triaxial_sensors_correlate_with_a_simulated_test(tmp_path):
    """12 triaxial sensors on the example box (grid of twice the mesh size over every plate); a test
    simulated on the box meshed twice as fine (0.2 % / 2 % noise) at those sensors pairs every one of
    the 12 target modes with its model mode at MAC >= 0.9."""
    out, js = tmp_path / "out", tmp_path / "pretest.json"
    r = run("pretest", BOX, "--sensors", 12, "--configurations", 0, "--out", out, "--json", js)
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    assert "suspension" not in d and d["configurations"] == []
    assert all(s["direction"] == "xyz" and "z_mm" in s for s in d["sensors"])
    pts, dofs = read_points_csv(out / "points.csv")
    assert len(pts) == 12 and len(dofs) == 36
    box = load_box(BOX)
    truth = box.build(None, box.mesh_size / 2)
    test = simulate_on_model(truth.model, solve_modes(truth.model, n_modes=12), pts, dofs,
                             noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=3).modes
    model = box.build()
    corr = correlate(test, model.model, solve_modes(model.model, n_modes=18))
    pairs = {p.test: p for p in corr.pairing.pairs}
    assert sorted(pairs) == list(range(12))
    assert all(pairs[k].model == k and pairs[k].mac >= 0.9 for k in range(12))


def test_bad_parameters_name_is_one_clear_line(tmp_path):
    r = run("pretest", CARD / "board.toml", "--parameters", "t_XYZ", "--json", tmp_path / "x.json")
    assert r.exit_code == 2 and "t_XYZ" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "x.json").exists()
