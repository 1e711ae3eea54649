"""Every command that takes a board.toml takes a box.toml (the top-level table decides), with the JSON keys
boards write: build (3-D pictures of the whole box with its ribs, VTU with the rib lines, CSV, JSON),
simulate-test with a 3-D excitation, correlate, update (the updated box.toml with its comments), localize
and study."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.box import load_box
from pcbdyn.cli import main

from box_helpers import POINTS, edited

RHO = 2700.0


def invoke(*args):
    res = CliRunner().invoke(main, [str(a) for a in args])
    assert res.exit_code == 0, res.output
    return res


def test_build_writes_json_csv_vtu_and_3d_pictures_of_the_box(tmp_path):
    path = edited(tmp_path, {"box.mesh_size": '"20 mm"', "analysis.modes": "2"})
    out, js = tmp_path / "out", tmp_path / "modes.json"
    res = invoke("build", path, "--out", out, "--json", js)
    data = json.loads(js.read_text())
    box = load_box(path)
    mass = sum(RHO * p.thickness * p.lengths[0] * p.lengths[1] for p in box.plates) + 0.080 + sum(
        RHO * r.height * r.width * np.linalg.norm(np.subtract(r.end, r.start)) for r in box.ribs)
    assert data["mass_kg"] == pytest.approx(mass, rel=1e-9) and len(data["modes"]) == 2
    assert data["modes"][0]["frequency_hz"] == pytest.approx(372, rel=0.02)
    assert data["modes"][0]["shape"] == "upper 99 %"  # the plates that carry the mode, not nodal lines
    assert "upper 99 %" in res.output
    import pyvista as pv

    grid = pv.read(str(out / "modes_base.vtu"))
    lines = int(np.sum(grid.celltypes == pv.CellType.LINE))
    assert lines == sum(len(s.conn) for s in box.build().model.sets.values() if s.etype == "beam2") > 0
    assert np.max(np.linalg.norm(grid.point_data["mode_2"], axis=1)) == pytest.approx(1.0)  # max |u| = 1
    pngs = sorted((out / "png").glob("modes_base_*.png"))
    assert len(pngs) == 2 and all(p.stat().st_size > 20000 for p in pngs)


def test_simulate_test_correlate_update_and_localize_on_a_box(tmp_path):
    model = edited(tmp_path, {"box.mesh_size": '"20 mm"', "analysis.modes": "6"}, name="box.toml")
    truth = edited(tmp_path, {"box.mesh_size": '"20 mm"', "analysis.modes": "6", "plates.3.E": '"63 GPa"'},
                   remove=("parameters",), name="truth.toml")
    uff, sim = tmp_path / "test.uff", tmp_path / "sim.json"
    invoke("simulate-test", truth, "--points", POINTS, "--excite", "0,20,110", "--excite-dir", "+x", "--seed", "1",
           "--out", uff, "--json", sim)
    s = json.loads(sim.read_text())
    assert s["excitation"]["direction"] == "+x" and s["excitation"]["z_m"] == pytest.approx(0.110)
    assert s["response_dofs"] == 429 and len(s["modes"]) == 6
    corr = tmp_path / "corr.json"
    invoke("correlate", truth, uff, "--json", corr, "--out", tmp_path / "corr")
    pairs = json.loads(corr.read_text())["pairs"]
    assert len(pairs) == 6 and min(p["mac"] for p in pairs) > 0.999
    assert (tmp_path / "corr" / "comac.png").stat().st_size > 10000
    up = tmp_path / "update.json"
    invoke("update", model, uff, "--params", "E_upper", "--json", up, "--no-mesh-check")  # the test is the model's mesh
    data = json.loads(up.read_text())
    assert data["parameters"]["E_upper"]["updated"] == pytest.approx(63e9, rel=1e-3)
    assert data["before"]["max_freq_error_pct"] > 1.0 > 0.01 > data["after"]["max_freq_error_pct"]
    updated = load_box(data["updated_board"])
    assert updated.quantity("plates.upper.E") == pytest.approx(63e9, rel=1e-3)
    assert "# x = 0; n = u x v = +x points into the box" in updated.path.read_text()
    loc = tmp_path / "loc.json"
    invoke("localize", model, uff, "--params", "E_upper,rho_upper,h_back", "--json", loc, "--out", tmp_path / "loc")
    assert json.loads(loc.read_text())["selected"] == ["E_upper"]
    assert (tmp_path / "loc" / "localisation.png").is_file()


def test_a_localisation_study_on_a_box(tmp_path):
    """A success-ratio study (thesis eqs. 5.65-5.66) whose model is a box.toml: with exact data TLS/QR-F finds
    the one wrong parameter, the upper plate's modulus, every time."""
    edited(tmp_path, {"box.mesh_size": '"20 mm"'}, name="box.toml")
    (tmp_path / "study.toml").write_text(
        f'[study]\ncase = "board"\nboard = "box.toml"\npoints = "{POINTS}"\nlevels_pct = [0, 0.5]\nshots = 3\n'
        'methods = ["tls-qrf"]\nequations = ["freq"]\n\n[truth]\nE_upper = "60 GPa"\n\n'
        '[case]\nn_modes = 6\nparams = ["E_upper", "h_side", "h_back"]\n')
    js = tmp_path / "study.json"
    invoke("study", tmp_path / "study.toml", "--json", js, "--quiet")
    data = json.loads(js.read_text())
    assert data["true_errors"] == ["E_upper"]
    exact = next(r for r in data["summary"] if r["level_pct"] == 0 and r["method"] == "tls-qrf")
    assert exact["mean"] == pytest.approx(100.0)
