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
    first = data["modes"][0]["effective_mass"]
    assert first["z"] == pytest.approx(64 / np.pi**4, rel=0.02)  # (mean sin)^4 / (mean sin^2)^2
    assert sorted(first) == ["rx", "ry", "rz", "x", "y", "z"] and first["x"] < 1e-12 and first["y"] < 1e-12
    assert "frequency [Hz]" in res.output and "m_eff z [%]" in res.output and "sum z [%]" in res.output
    csv = (out / "modes_base.csv").read_text().splitlines()
    assert csv[0].startswith("mode,frequency [Hz],m_eff x [%]") and len(csv) == 5
    z_pct = float(csv[1].split(",")[csv[0].split(",").index("m_eff z [%]")])  # the same percent as the console
    assert z_pct == pytest.approx(round(100 * first["z"], 2), abs=1e-9) and f"{z_pct:.2f}" in res.output
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


def test_a_smaller_rerun_leaves_no_stale_files_and_keeps_the_users(tmp_path, monkeypatch):
    """--all-configs with 4 modes, then --config loaded with 2: the base model's files and the
    pictures of modes 3-4 go (the folder's manifest lists what the earlier run wrote); the user's
    files in the folder stay. The pictures get the configuration's title and outlines."""
    import pcbdyn.report.pictures as pictures

    calls = []
    real = pictures.mode_pictures
    monkeypatch.setattr(pictures, "render_child", lambda *args: False)  # matplotlib 3-D views: quicker
    monkeypatch.setattr(pictures, "mode_pictures", lambda *a, **k: calls.append(k) or real(*a, **k))
    board = write_board(tmp_path, PLATE)
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["build", str(board), "--all-configs", "--out", str(out)])
    assert res.exit_code == 0, res.output

    def files():
        return sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())

    assert [f for f in files() if f.startswith("png/")] == [f"png/modes_{c}_{k}.png" for c in ("base", "loaded")
                                                            for k in ("01", "02", "03", "04")]
    assert [c["title"] for c in calls] == ["simply supported plate [base]", "simply supported plate [loaded]"]
    kinds = [[o["kind"] for o in c["outlines"]] for c in calls]
    assert kinds[0].count("fixture") == 4 and "mass" not in kinds[0]
    assert [o["label"] for o in calls[1]["outlines"] if o["kind"] == "mass"] == ["m1 (loaded)"]
    (out / "notes.txt").write_text("mine")
    (out / "png" / "sketch.png").write_bytes(b"mine")
    board.write_text(board.read_text().replace("modes = 4", "modes = 2"))
    res = CliRunner().invoke(main, ["build", str(board), "--config", "loaded", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert files() == ["modes_loaded.csv", "modes_loaded.vtu", "notes.txt", "pcbdyn-manifest.json",
                       "png/modes_loaded_01.png", "png/modes_loaded_02.png", "png/sketch.png"]
    assert "removed 8 file(s) an earlier run wrote" in res.output


def test_an_interrupt_while_pictures_are_drawn_leaves_the_earlier_run_whole(tmp_path, monkeypatch):
    """Ctrl-C in the middle of the pictures (simulated: the renderer raises after its first picture): the
    --out folder is the earlier run's, file for file, its manifest matching; it was half old, half new."""
    import hashlib

    import pcbdyn.report.pictures as pictures
    from pcbdyn.report.manifest import MANIFEST

    monkeypatch.setattr(pictures, "render_child", lambda *args: False)  # matplotlib 3-D views: quicker
    board = write_board(tmp_path, PLATE.replace("modes = 4", "modes = 2"))
    out = tmp_path / "out"
    assert CliRunner().invoke(main, ["build", str(board), "--out", str(out)]).exit_code == 0
    (out / "notes.txt").write_text("mine")
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    real = pictures.mode_pictures

    def interrupted(vtu, model, frequencies, shapes, folder, **kw):
        real(vtu, model, frequencies[:1], shapes[:, :1], folder, **kw)
        raise KeyboardInterrupt

    monkeypatch.setattr(pictures, "mode_pictures", interrupted)
    board.write_text(board.read_text().replace('E = "22 GPa"', 'E = "30 GPa"'))
    res = CliRunner().invoke(main, ["build", str(board), "--out", str(out)])
    assert res.exit_code == 1 and "Aborted" in res.output  # click turns Ctrl-C into "Aborted!"
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    listed = json.loads((out / MANIFEST).read_text())["files"]
    assert len(listed) == 4 and all(hashlib.sha256((out / r).read_bytes()).hexdigest() == d for r, d in listed.items())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["board.toml", "out"]


def test_a_band_below_the_first_mode_is_an_answer_with_a_warning(tmp_path):
    """[analysis] f_max below the first mode: exit 0, no modes, and the console and the JSON name the first
    frequency above the band (the plate formula's (1,1) mode), not a silent empty table."""
    board = write_board(tmp_path, PLATE.replace("[analysis]", '[analysis]\nf_max = "100 Hz"'))
    js = tmp_path / "modes.json"
    res = CliRunner().invoke(main, ["build", str(board), "--json", str(js)])
    assert res.exit_code == 0, res.output
    data = json.loads(js.read_text())
    assert data["modes"] == []
    first = float(data["warning"].split("the first is at ")[1].split(" Hz")[0])
    assert first == pytest.approx(navier(1, 1), rel=0.01) and first > 100.0
    assert f"warning: {data['warning']}" in res.output
