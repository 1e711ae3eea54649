"""Each kind of bad board.toml gives one clear message naming the file, the field and the fix."""

import pytest

from pcbdyn.board import BoardError, load_board

from board_helpers import write_board
from data_files import board_text

GOOD = board_text("bad_input_good.toml")


def test_the_good_board_reads(tmp_path):
    b = load_board(write_board(tmp_path, GOOD))
    assert [c.ref for c in b.components] == ["U1", "U2"]
    assert b.components[0].mass == pytest.approx(0.014)
    hinged = load_board(write_board(tmp_path, GOOD.replace('k_rot = "1e4 N*m/rad/m"', 'k_rot = "0 N*m/rad/m"')))
    assert hinged.fixtures[0].k_rot == 0.0


CASES = {
    "malformed TOML": (('thickness = "1.6 mm"', 'thickness = "1.6 mm'), [r"board.toml: not valid TOML", r"at line 5"]),
    "missing field": (('thickness = "1.6 mm"\n', ""), [r"board\.thickness: missing; add thickness"]),
    "wrong unit": (('thickness = "1.6 mm"', 'thickness = "1.6 kg"'), [r"board\.thickness: '1.6 kg'", "expected a unit like 'mm'"]),
    "negative thickness": (('thickness = "1.6 mm"', 'thickness = "-1.6 mm"'), [r"board\.thickness: must be positive"]),
    "part off the board": (('at = ["30 mm", "40 mm"]', 'at = ["5 mm", "40 mm"]'),
                           [r"components\[0\]\.at: part U1 .* does not lie on the board"]),
    "overlapping parts": (('at = ["75 mm", "40 mm"]', 'at = ["55 mm", "40 mm"]'),
                          [r"components\[1\]\.at: part U2 overlaps part U1"]),
    "unknown package": (('package = "PGA"', 'package = "PGB"'), [r"components\[0\]\.package: unknown package 'PGB'",
                                                              "did you mean 'PGA'"]),
    "bad model name": (('model = "spread"', 'model = "lumpy"'), [r"components\[1\]\.model: unknown part model 'lumpy'",
                                                                "did you mean 'lumped'"]),
    "edge not on outline": (('edge = "x=0"', 'edge = "x=50 mm"'), [r"fixtures\[0\]\.edge: 'x=50 mm' is not an edge"]),
    "unknown fixture type": (('type = "wedge_lock"', 'type = "wedgelock"'),
                             [r"fixtures\[0\]\.type: unknown fixture type 'wedgelock'", "did you mean 'wedge_lock'"]),
    "parameter target missing": (('target = "components.U1.thickness"', 'target = "components.U9.thickness"'),
                                 [r"parameters\[0\]\.target: 'components\.U9\.thickness' is not a quantity"]),
    "bounds reversed": (('bounds = ["2 mm", "10 mm"]', 'bounds = ["10 mm", "2 mm"]'),
                        [r"parameters\[0\]\.bounds: lower bound '10 mm' is not below the upper '2 mm'; swap"]),
    "bounds exclude value": (('bounds = ["2 mm", "10 mm"]', 'bounds = ["4 mm", "10 mm"]'),
                             [r"parameters\[0\]\.bounds: the current value 0\.0035 .* outside"]),
    "bounds wrong unit": (('bounds = ["2 mm", "10 mm"]', 'bounds = ["2 g", "10 g"]'),
                          [r"parameters\[0\]\.bounds\[0\]: '2 g' has unit 'g'"]),
    "misspelt field": (('mesh_size = "10 mm"', 'mesh_sise = "10 mm"'), [r"board\.mesh_sise: unknown field; did you mean 'mesh_size'"]),
    "part without package lacks mass": (('mass = "5 g"\n', ""), [r"components\[1\]\.mass: missing: a part without a package"]),
    "mass off the board": (('at = ["90 mm", "10 mm"]', 'at = ["190 mm", "10 mm"]'), [r"masses\[0\]\.at: .* not on the board"]),
    "poisson ratio out of range": (("nu = 0.15", "nu = 0.6"), [r"board\.material\.nu: must lie between -1\.0 and 0\.5"]),
    "duplicate part ref": (('ref = "U2"', 'ref = "U1"'), [r"components\[1\]\.ref: 'U1' is used by another part"]),
    "field of another fixture type": (('k_rot = "1e4 N*m/rad/m"', 'k_rot = "1e4 N*m/rad/m"\nat = ["1 mm", "1 mm"]'),
                                      [r"fixtures\[0\]\.at: a wedge_lock fixture has no at; remove it"]),
    "wedge lock without k_rot": (('k_rot = "1e4 N*m/rad/m"\n', ""), [r"fixtures\[0\]\.k_rot: missing"]),
}


@pytest.mark.parametrize("kind", sorted(CASES))
def test_bad_board_gives_one_clear_message(tmp_path, kind):
    (old, new), patterns = CASES[kind]
    assert old in GOOD
    path = write_board(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(BoardError) as err:
        load_board(path)
    msg = str(err.value)
    assert msg.startswith("board.toml: "), msg
    assert "\n" not in msg
    for pat in patterns:
        assert __import__("re").search(pat, msg), f"{pat!r} not in {msg!r}"


def test_unknown_configuration_is_named(tmp_path):
    from pcbdyn.board import build_model

    b = load_board(write_board(tmp_path, GOOD))
    with pytest.raises(BoardError, match="configuration 'c9' does not exist"):
        build_model(b, "c9")
