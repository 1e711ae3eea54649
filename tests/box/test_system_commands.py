"""The commands on a system (a box.toml with [[cards]]): build names each mode's card or plates and reports a
Craig-Bampton reduction's error; vibe judges every part of every card; bad [[cards]] entries are one clear
message naming the file and field."""

import json
import shutil

import pytest
from click.testing import CliRunner
from system_helpers import EXAMPLES

from pcbdyn.box import BoxError, load_box
from pcbdyn.cli import main


@pytest.fixture
def example(tmp_path):
    for f in EXAMPLES.iterdir():
        shutil.copy(f, tmp_path)
    return tmp_path / "box.toml"


def _edit(path, old, new):
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def test_build_names_the_cards_modes_and_reports_the_reduction(example, tmp_path):
    _edit(example, "v = [1, 0, 0]\n", "v = [1, 0, 0]\nreduce = 30\n")
    res = CliRunner().invoke(main, ["build", str(example), "--no-pictures", "--json", str(tmp_path / "b.json")])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "b.json").read_text())
    shapes = [m["shape"] for m in data["modes"]]
    assert shapes[0] == "shelf 100 %" and "ribs_card 100 %" in shapes and any("upper" in s for s in shapes)
    shares = data["modes"][0]["shares"]
    assert set(shares) == {"left", "right", "back", "upper", "ribs_card", "shelf"} and shares["shelf"] > 0.99
    assert sum(shares.values()) == pytest.approx(1.0)
    assert data["reduction"]["cards"] == {"shelf": 30} and 0 <= data["reduction"]["max_error_pct"] < 0.5
    assert "Craig-Bampton: shelf 30 modes" in res.output


def test_vibe_judges_every_part_of_every_card(example, tmp_path):
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["vibe", str(example), "--psd", "gevs-accept", "--json", str(tmp_path / "v.json"),
                                    "--out", str(out), "--exclude", "shelf.U2"])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "v.json").read_text())
    assert sorted(data["cards"]) == ["ribs_card", "shelf"] and data["chassis_source"] == "computed"
    assert sorted(p["ref"] for p in data["cards"]["ribs_card"]["parts"]) == ["U1", "U2"]
    assert [p["ref"] for p in data["cards"]["shelf"]["parts"]] == ["U1"]
    octave = data["cards"]["shelf"]["octave_rule"]
    assert octave["chassis_hz"] == pytest.approx(data["chassis_hz"]) and octave["board_hz"] < octave["chassis_hz"]
    assert (out / "shelf" / "parts.csv").is_file() and (out / "ribs_card" / "board_map.png").is_file()


@pytest.mark.parametrize("old, new, message", [
    ('board = "card_ribs.toml"', 'board = "nope.toml"', r"box.toml: cards\[0\].board: 'nope.toml' does not exist"),
    ("v = [0, 0, 1]", "v = [0.1, 0, 1]", r"box.toml: cards\[0\].v: is not at right angles to u"),
    ('origin = ["20 mm", "148.2 mm", "20 mm"]', 'origin = ["20 mm", "130 mm", "20 mm"]',
     r"fixture 's1' \(standoff\) of card 'ribs_card' \(card_ribs.toml\) touches nothing: the nearest, rib "
     r"'back_h1', is 18.2 mm away"),
])
def test_bad_cards_are_named(example, old, new, message):
    _edit(example, old, new)
    with pytest.raises(BoxError, match=message):
        load_box(example)


def test_a_card_whose_board_is_bad_names_both_files(example):
    _edit(example.with_name("card_guides.toml"), 'thickness = "1.6 mm"', 'thickness = "-1 mm"')
    with pytest.raises(BoxError, match=r"box.toml: cards\[1\].board: card 'shelf': card_guides.toml: board.thickness"):
        load_box(example)


def test_a_simulated_test_on_cards_and_plates_correlates(example, tmp_path):
    """simulate-test at the example's points (on the plates in x, y, z and on the cards normal to them),
    excited on the shelf, then correlate: every test mode pairs with its model mode."""
    uff, js = tmp_path / "test.uff", tmp_path / "c.json"
    res = CliRunner().invoke(main, ["simulate-test", str(example), "--points", str(example.with_name("points.csv")),
                                    "--excite", "100,40,60", "--excite-dir", "-z", "--modes", "8", "--out", str(uff)])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(main, ["correlate", str(example), str(uff), "--json", str(js)])
    assert res.exit_code == 0, res.output
    pairs = json.loads(js.read_text())["pairs"]
    assert [p["test_mode"] for p in pairs] == [p["model_mode"] for p in pairs] == list(range(1, 9))
    assert min(p["mac"] for p in pairs) > 0.99
