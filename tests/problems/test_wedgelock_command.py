"""``pcbdyn wedgelock`` (issue 20) on a simulated test of the card in guides of 5000 N*m/rad/m: springs,
the stiffness within a factor 1.3, every mode within 1 % after; the JSON contract, the pictures and the
updated board; clear errors without results when there is nothing to fit."""

import json
import math

import pytest
import tomlkit
from click.testing import CliRunner
from wedge_tests import BOARD, EXAMPLE, simulated_test

from pcbdyn.board import load_board
from pcbdyn.cli import main
from pcbdyn.testdata import TestData, write_uff

#: the module's fixtures are made once: its tests run on one xdist worker
pytestmark = pytest.mark.xdist_group("wedgelock_command")

TRUE_K = 5000.0


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    d = tmp_path_factory.mktemp("wedge")
    (d / "board.toml").write_text(BOARD.read_text())
    write_uff(d / "test.uff", simulated_test(TRUE_K, TRUE_K))
    res = run("wedgelock", d / "board.toml", d / "test.uff", "--noise", "f=0.2,shape=2", "--out", d / "out",
              "--json", d / "wedge.json")
    assert res.exit_code == 0, res.output
    return d, res, json.loads((d / "wedge.json").read_text())


def test_springs_recovered(fitted):
    """Guides at 5000 N*m/rad/m (the card near the middle of its hinged-clamped range): "springs", one
    stiffness for both guides within a factor 1.3 (and its 1-sigma factor covering the truth three times
    over), every paired mode within 1 % after the fit."""
    _, _, d = fitted
    assert d["decision"] == "springs" and not d["per_guide"]
    assert d["extremes"]["clamped"]["max_abs_freq_error_pct"] > 10  # far from clamped: step 2 was needed
    for name in ("bottom_guide", "top_guide"):
        k, f = d["k_rot"][name]["value"], d["k_rot"][name]["factor_1sigma"]
        assert max(k / TRUE_K, TRUE_K / k) < 1.3
        assert 1.0 < f and abs(math.log(k / TRUE_K)) < 3 * math.log(f)
    assert len(d["after"]["pairs"]) == 5
    assert all(abs(q["df_pct"]) < 1.0 for q in d["after"]["pairs"])
    assert d["after"]["max_freq_error_pct"] <= d["before"]["max_freq_error_pct"] + 1e-9


def test_json_contract(fitted):
    _, _, d = fitted
    for kind in ("hinged", "clamped"):
        ext = d["extremes"][kind]
        assert isinstance(ext["max_abs_freq_error_pct"], float) and len(ext["pairs"]) == 5
        assert {"test_mode", "model_mode", "f_test_hz", "f_model_hz", "df_pct", "mac"} <= set(ext["pairs"][0])
        assert all(q["mac"] > 0.5 for q in ext["pairs"])
    assert d["decision"] in ("clamped", "springs")
    assert set(d["k_rot"]) == {"bottom_guide", "top_guide"}
    assert all({"value", "factor_1sigma"} <= set(v) for v in d["k_rot"].values())
    assert isinstance(d["before"]["max_freq_error_pct"], float) and isinstance(d["after"]["max_freq_error_pct"], float)
    h = d["history"]
    assert h and h[0]["iteration"] == 0 and set(h[-1]["k_rot"]) == {"bottom_guide", "top_guide"}
    assert h[-1]["k_rot"]["bottom_guide"] == pytest.approx(d["k_rot"]["bottom_guide"]["value"])


def test_printed_values_are_the_json_values(fitted):
    """What the run prints for each guide (the fit's 'start -> end' line and the stiffness table) is the JSON's
    value (issue 40: the summary printed 'guide_y0 4783 -> 2.936' while the JSON kept 4783)."""
    _, res, d = fitted
    for name in ("bottom_guide", "top_guide"):
        k = d["k_rot"][name]["value"]
        assert f"{name} {d['start'][name]:.4g} -> {k:.4g}" in res.output
        assert f"{k:>20.5g}" in res.output


def test_outputs_and_updated_board(fitted):
    """Tables, pictures and the board with the fitted stiffness in --out, its comments kept, giving back
    the fitted value."""
    d, res, data = fitted
    for name in ("extremes.txt", "stiffness.txt", "correlation.txt", "history.png", "frequencies_vs_k.png"):
        assert (d / "out" / name).stat().st_size > 0, name
    updated = d / "out" / "board.updated.toml"
    assert data["updated_board"] == str(updated)
    text = updated.read_text()
    assert "# The thesis' six-part card held by two wedge-lock guides" in text
    fixtures = {f["name"]: f["k_rot"] for f in tomlkit.parse(text)["fixtures"]}
    assert fixtures["bottom_guide"].endswith("N*m/rad/m")
    board = load_board(updated)
    assert board.fixture("top_guide").k_rot == pytest.approx(data["k_rot"]["top_guide"]["value"], rel=1e-9)
    assert "decision: springs" in res.output


def test_too_few_modes_writes_nothing(tmp_path):
    """A one-mode test of guides that are not clamped: an error naming the reason, exit code 2, and no
    JSON or updated board."""
    (tmp_path / "board.toml").write_text(BOARD.read_text())
    data = simulated_test(TRUE_K, TRUE_K)
    write_uff(tmp_path / "one.uff", TestData(data.points, data.modes.subset([0])))
    res = run("wedgelock", tmp_path / "board.toml", tmp_path / "one.uff", "--json", tmp_path / "w.json")
    assert res.exit_code == 2
    assert "too few to fit a stiffness" in res.output and "no stiffness is reported" in res.output
    assert not (tmp_path / "w.json").exists() and not (tmp_path / "board.updated.toml").exists()


def test_board_without_guides(tmp_path):
    res = run("wedgelock", EXAMPLE.parent / "six_part_card" / "board.toml", "--frequencies",
              EXAMPLE / "measured_frequencies_table_7_12.csv")
    assert res.exit_code == 2 and "no [[fixtures]] of type \"wedge_lock\"" in res.output


def test_a_sparse_grid_prints_the_pairing_s_aliasing_warnings(tmp_path):
    """The test read at 6 points in two rows near the guides (issue 38): on them the card's first mode and its
    eighth look alike (AutoMAC 0.99); wedgelock says so, and the clamped extreme still pairs test mode k with
    model mode k (by frequency within what the grid cannot tell apart)."""
    import numpy as np

    from pcbdyn.testdata import MeasuredModes

    td = simulated_test(TRUE_K, TRUE_K)
    m = td.modes
    xyz = np.round(m.dof_xyz(), 5)
    xs, ys = np.unique(xyz[:, 0]), np.unique(xyz[:, 1])
    keep = np.flatnonzero(np.isin(xyz[:, 0], xs[[2, 4, 6]]) & np.isin(xyz[:, 1], ys[[0, 6]]))
    sparse = MeasuredModes(m.points, m.dofs.take(keep), m.frequencies, m.shapes[keep], m.damping)
    (tmp_path / "board.toml").write_text(BOARD.read_text())
    write_uff(tmp_path / "sparse.uff", TestData(m.points, sparse))
    res = run("wedgelock", tmp_path / "board.toml", tmp_path / "sparse.uff", "--json", tmp_path / "w.json",
              "--out", tmp_path / "out")
    assert res.exit_code == 0, res.output
    d = json.loads((tmp_path / "w.json").read_text())
    assert any(w.startswith("configuration base: model modes 1 (") and "look alike" in w for w in d["warnings"])
    assert all(f"warning: {w}" in res.stderr for w in d["warnings"])
    assert [(q["test_mode"], q["model_mode"]) for q in d["extremes"]["clamped"]["pairs"]] == [(k, k) for k in
                                                                                            range(1, 6)]
