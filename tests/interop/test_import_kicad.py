"""`pcbdyn import-kicad`: a KiCad board written by kiutils (known outline, cut-outs, stack-up and
parts) gives the expected board.toml, whose model weighs the parts plus the laminate; the bundled
example's board builds; bad input gets clear errors."""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from kicad_boards import CUT_RECT, MAP, NOTCH, PARTS, outline_kicad, write_board

from pcbdyn.board import build_model, load_board
from pcbdyn.cli import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "kicad_board"
Y_MAX, X_MIN = 110.0, 50.0  # KiCad bounds of the test board (mm): the board frame's origin


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def board_frame(x, y):
    return (x - X_MIN) * 1e-3, (Y_MAX - y) * 1e-3


def imported(tmp_path, circle=True, parts=PARTS, map_text=MAP):
    write_board(tmp_path / "t.kicad_pcb", parts, circle)
    (tmp_path / "map.toml").write_text(map_text)
    res = run("import-kicad", tmp_path / "t.kicad_pcb", "--packages", tmp_path / "map.toml",
              "--out", tmp_path / "board.toml", "--json", tmp_path / "import.json")
    return res


def test_kicad_board_gives_the_expected_board_toml(tmp_path):
    res = imported(tmp_path)
    assert res.exit_code == 0, res.output
    board = load_board(tmp_path / "board.toml")
    want = sorted(board_frame(x, y) for x, y in outline_kicad())
    np.testing.assert_allclose(sorted(map(tuple, board.outline.vertices)), want, atol=1e-12)
    rect_hole, circle_hole = board.outline.holes
    (x0, y0), (x1, y1) = CUT_RECT
    np.testing.assert_allclose(sorted(map(tuple, rect_hole)), sorted([board_frame(x0, y0), board_frame(x1, y0),
                                                                       board_frame(x1, y1), board_frame(x0, y1)]))
    np.testing.assert_allclose(circle_hole.mean(axis=0), board_frame(120.0, 90.0), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(circle_hole - circle_hole.mean(axis=0), axis=1), 2e-3)
    assert board.plate.t == pytest.approx(1.6e-3, rel=1e-12)
    assert [L.thickness for L in board.plate.layers] == pytest.approx([1e-5, 3.5e-5, 1.51e-3, 3.5e-5, 1e-5])
    parts = {c.ref: c for c in board.components}
    assert set(parts) == {"U1", "U2", "C1", "X1"}
    u1, u2, c1, x1 = parts["U1"], parts["U2"], parts["C1"], parts["X1"]
    assert u1.package == "CQFP" and u1.mass == pytest.approx(8.6e-3) and u1.size == pytest.approx((13e-3, 13e-3))
    np.testing.assert_allclose(u1.at, board_frame(75.0, 45.0), atol=1e-12)
    # U2: bottom side, 30 deg, courtyard centre 1.7 mm along its own x from the footprint origin
    c30, s30 = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(u2.at, board_frame(110.0 + 1.7 * c30, 55.0 - 1.7 * s30), atol=1e-9)
    assert u2.rotation == pytest.approx(math.radians(30)) and u2.size == pytest.approx((7.4e-3, 5.4e-3))
    assert u2.mass == pytest.approx(0.08e-3) and u2.package is None
    assert c1.rotation == pytest.approx(math.pi / 2) and c1.model == "lumped" and c1.height == pytest.approx(0.012)
    np.testing.assert_allclose(c1.at, board_frame(100.8, 85.0), atol=1e-12)
    # X1 hangs 4 mm over the bottom edge: clipped to the board, its mass kept
    assert x1.size == pytest.approx((10e-3, 12e-3)) and x1.mass == pytest.approx(1e-3)
    np.testing.assert_allclose(x1.at, (10e-3, 6e-3), atol=1e-12)
    data = json.loads((tmp_path / "import.json").read_text())
    assert data["unmapped"] == [{"footprint": "Connector_Weird:Thing", "count": 2, "refs": ["J1", "J2"]}]
    assert data["ignored"] == 1 and data["kept_out"] == []
    holes = {s["ref"]: s for s in data["standoff_candidates"]}
    assert set(holes) == {"H1", "H2"}
    np.testing.assert_allclose(holes["H1"]["at_m"], board_frame(55.0, 35.0), atol=1e-12)
    assert holes["H2"]["diameter_m"] == pytest.approx(6.4e-3)
    text = (tmp_path / "board.toml").read_text()
    assert "Connector_Weird:Thing  x2  (J1, J2)" in text and "bottom side" in text
    # the commented candidates are board.toml as it stands: uncommented, the board loads with them
    live = re.sub(r"^# (\[\[fixtures\]\]|name|type|at|diameter)", r"\1", text, flags=re.M)
    (tmp_path / "held.toml").write_text(live)
    held = load_board(tmp_path / "held.toml")
    assert [(f.type, f.name) for f in held.fixtures] == [("standoff", "H1"), ("standoff", "H2")]


def test_imported_model_weighs_the_parts_and_the_laminate(tmp_path):
    assert imported(tmp_path, circle=False).exit_code == 0
    bm = build_model(load_board(tmp_path / "board.toml"))
    per_area = 2 * 1e-5 * 1300.0 + 2 * 3.5e-5 * 8960.0 + 1.51e-3 * 1850.0  # masks, copper, FR4 core [kg/m^2]
    (x0, y0), (x1, y1) = CUT_RECT
    area = (100.0 * 80.0 - NOTCH[0] * NOTCH[1] - (x1 - x0) * (y1 - y0)) * 1e-6
    parts = 8.6e-3 + 0.08e-3 + 2e-3 + 1e-3  # CQFP family, SOIC, capacitor, header
    assert bm.mass() == pytest.approx(parts + per_area * area, rel=1e-9)


def test_overlapping_parts_are_kept_out_and_listed(tmp_path):
    over = PARTS + [("C9", "Capacitor_THT:CP_Radial_D10.0mm_P5.00mm", (76.0, 46.0, 0.0), "B",
                     ((-2.0, -2.0), (2.0, 2.0)), None)]
    assert imported(tmp_path, parts=over).exit_code == 0
    data = json.loads((tmp_path / "import.json").read_text())
    assert data["kept_out"] == [{"ref": "C9", "footprint": over[-1][1], "reason": "overlaps U1"}]
    assert "C9" not in {c.ref for c in load_board(tmp_path / "board.toml").components}


def test_bundled_example_builds(tmp_path):
    out = tmp_path / "board.toml"
    res = run("import-kicad", EXAMPLE / "board.kicad_pcb", "--packages", EXAMPLE / "map.toml", "--out", out)
    assert res.exit_code == 0, res.output
    assert out.read_text() == (EXAMPLE / "board.toml").read_text()  # the bundled board.toml is this output
    res = run("build", out, "--no-pictures", "--json", tmp_path / "modes.json")
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "modes.json").read_text())
    assert len(data["modes"]) == load_board(out).analysis.modes and data["modes"][0]["frequency_hz"] > 0


def test_bad_input_gets_clear_errors(tmp_path):
    write_board(tmp_path / "t.kicad_pcb")
    (tmp_path / "map.toml").write_text(MAP)
    corrupt = tmp_path / "corrupt.kicad_pcb"
    corrupt.write_text((tmp_path / "t.kicad_pcb").read_text()[:2000])
    res = run("import-kicad", corrupt, "--packages", tmp_path / "map.toml", "--out", tmp_path / "a.toml")
    assert res.exit_code == 2 and "corrupt.kicad_pcb: not a readable KiCad board" in res.output
    open_edge = tmp_path / "open.kicad_pcb"
    text = (tmp_path / "t.kicad_pcb").read_text()
    first_line = re.search(r"^\s*\(gr_line .*\)\n", text, re.M)  # one edge of the outline removed
    open_edge.write_text(text.replace(first_line.group(0), "", 1))
    res = run("import-kicad", open_edge, "--packages", tmp_path / "map.toml", "--out", tmp_path / "b.toml")
    assert res.exit_code == 2 and "open.kicad_pcb: Edge.Cuts" in res.output and "do not close" in res.output
    bad_map = tmp_path / "bad_map.toml"
    bad_map.write_text('[footprints]\n"Package_QFP:*" = { package = "CQFP", colour = "red" }\n')
    res = run("import-kicad", tmp_path / "t.kicad_pcb", "--packages", bad_map, "--out", tmp_path / "c.toml")
    assert res.exit_code == 2 and "bad_map.toml" in res.output and "colour" in res.output
    no_family = tmp_path / "no_family.toml"
    no_family.write_text(MAP.replace('"CQFP"', '"QFP64"'))
    res = run("import-kicad", tmp_path / "t.kicad_pcb", "--packages", no_family, "--out", tmp_path / "d.toml")
    assert res.exit_code == 2 and "d.toml" in res.output and "unknown package 'QFP64'" in res.output
    assert "Traceback" not in res.output
    assert not any((tmp_path / f"{n}.toml").exists() for n in "abcd")
    (tmp_path / "kept.toml").write_text("# my own board\n")
    res = run("import-kicad", tmp_path / "t.kicad_pcb", "--packages", tmp_path / "map.toml", "--out",
              tmp_path / "kept.toml")
    assert res.exit_code == 2 and (tmp_path / "kept.toml").read_text() == "# my own board\n"
