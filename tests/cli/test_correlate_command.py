"""`pcbdyn simulate-test` and `pcbdyn correlate` on the six-part card (issue 4 acceptance).

The card is the thesis' free six-part card (examples/six_part_card/board.toml, as shipped); the
measurement grid is examples/six_part_card/points.csv (the node lines of the thesis' mesh).
"""

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.board import build_model, load_board
from pcbdyn.cli import main
from pcbdyn.correlation import mac
from pcbdyn.fe.assembly import assemble
from reference import load
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import Points, TestData, read_points_csv, read_uff, write_uff

#: the module's fixtures are made once: its tests run on one xdist worker
pytestmark = pytest.mark.xdist_group("correlate_command")

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"
POINTS = EXAMPLE / "points.csv"
U1 = 'ref = "U1"\npackage = "PGA"\nat = ["40.5 mm", "38.14 mm"]\n'
NOISE = {"f": 0.2, "shape": 2.0, "frf": 1.0}


def card_text(u1_thickness=None) -> str:
    text = (EXAMPLE / "board.toml").read_text()
    assert U1 in text
    if u1_thickness is not None:
        text = text.replace(U1, U1 + f'thickness = "{u1_thickness}"\n')
        # t_PGA ties U1 and U6 to one starting value: the "true" board needs no parameters
        text = re.sub(r"\[\[parameters\]\]\n(?:.+\n)+\n?", "", text)
    return text


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def card(tmp_path_factory):
    d = tmp_path_factory.mktemp("card")
    (d / "board.toml").write_text(card_text())
    noise = ",".join(f"{k}={v}" for k, v in NOISE.items())
    res = run("simulate-test", d / "board.toml", "--points", POINTS, "--excite", "135,63.57", "--noise", noise,
              "--seed", 3, "--df", 2, "--out", d / "noisy.uff", "--json", d / "sim.json")
    assert res.exit_code == 0, res.output
    return d


def test_points_are_the_thesis_grid():
    grid = load("thesis_tables.json")
    lines = grid["cases"]["T7.4_real_pcb_free"]["inputs"]["geometry_mm"]
    pts, dofs = read_points_csv(POINTS)
    X, Y = np.meshgrid(lines["x_lines"], lines["y_lines"])
    np.testing.assert_allclose(np.sort(pts.xyz[:, 0] * 1e3), np.sort(X.ravel()), atol=1e-9)
    np.testing.assert_allclose(np.sort(pts.xyz[:, 1] * 1e3), np.sort(Y.ravel()), atol=1e-9)
    assert np.all(dofs.directions == [0, 0, 1])


def test_noise_free_simulation_is_the_model_and_its_frf_peaks_at_the_modes(tmp_path):
    (tmp_path / "board.toml").write_text(card_text())
    res = run("simulate-test", tmp_path / "board.toml", "--points", POINTS, "--excite", "135 mm, 63.57 mm",
              "--f-range", "100,1300", "--df", 0.5, "--kind", "receptance", "--out", tmp_path / "t.uff")
    assert res.exit_code == 0, res.output
    data = read_uff(tmp_path / "t.uff")
    modes = solve_modes(build_model(load_board(tmp_path / "board.toml")).model, n_modes=7)
    # UFF 55 holds frequencies in E13.5: six significant digits
    np.testing.assert_allclose(data.modes.frequencies, modes.frequencies, rtol=5e-6)
    H = np.abs(data.frfs.H[:, :, 0])
    drive = int(np.flatnonzero(data.frfs.response.point_ids == data.frfs.reference.point_ids[0])[0])
    f = data.frfs.frequencies
    assert f[0] == pytest.approx(100) and f[-1] == pytest.approx(1300) and data.frfs.kind == "receptance"
    # every resonance below 1300 Hz seen at the driving point (which is not on a nodal line of the
    # first modes) is a local maximum of |H| within half a percent of the natural frequency
    peaks = f[1:-1][(H[1:-1, drive] > H[:-2, drive]) & (H[1:-1, drive] > H[2:, drive])]
    for fn in modes.frequencies[:3]:
        assert np.min(np.abs(peaks - fn)) / fn < 0.005


def test_correlating_a_board_with_its_own_noisy_test_pairs_every_mode(card):
    res = run("correlate", card / "board.toml", card / "noisy.uff", "--json", card / "c.json")
    assert res.exit_code == 0, res.output
    data = json.loads((card / "c.json").read_text())
    pairs = data["pairs"]
    assert [p["test_mode"] for p in pairs] == list(range(1, 8))
    assert [p["model_mode"] for p in pairs] == list(range(1, 8))
    # frequencies carry +-0.2 % uniform noise (thesis eq. 5.72): df within that, MAC near 1 (2 % shape noise)
    bound = 100 * (1 / (1 - NOISE["f"] / 100) - 1)
    assert all(abs(p["df_pct"]) <= bound for p in pairs)
    assert all(p["mac"] > 0.99 for p in pairs)
    assert data["unpaired_test_modes"] == []
    assert min(data["comac"].values()) > 0.99
    assert "f_test [Hz]" in res.output and "MAC" in res.output
    sim = json.loads((card / "sim.json").read_text())
    f_sim = np.array([m["frequency_hz"] for m in sim["modes"]])
    f_model = np.array(sim["model_frequencies_hz"])
    assert np.all(np.abs(f_sim / f_model - 1) <= NOISE["f"] / 100) and np.any(f_sim != f_model)
    assert sim["noise_pct"] == {"frequency": NOISE["f"], "shape": NOISE["shape"], "frf": NOISE["frf"]}


@pytest.fixture(scope="module")
def thick(card):
    """A 'true' card whose U1 is 5 mm thick instead of 3.5 mm, tested noise-free, against the model."""
    d = card
    (d / "thick.toml").write_text(card_text("5 mm"))
    res = run("simulate-test", d / "thick.toml", "--points", POINTS, "--excite", "135,63.57", "--df", 5,
              "--out", d / "thick.uff")
    assert res.exit_code == 0, res.output
    res = run("correlate", d / "board.toml", d / "thick.uff", "--out", d / "out", "--json", d / "thick.json")
    assert res.exit_code == 0, res.output
    return d, json.loads((d / "thick.json").read_text()), res.output


def test_thicker_part_gives_the_pair_table_physics_predicts(thick):
    d, data, _ = thick
    model, true = build_model(load_board(d / "board.toml")), build_model(load_board(d / "thick.toml"))
    assert np.array_equal(model.model.nodes, true.model.nodes)
    # equivalent thickness keeps the part's mass (thesis eq. 7.7): only stiffness (and rotary inertia) change
    assert true.mass() == pytest.approx(model.mass(), rel=1e-12)
    n_model = len(data["model_frequencies_hz"])
    ma, mt = solve_modes(model.model, n_modes=n_model), solve_modes(true.model, n_modes=7)
    # independent pairing on the full FE shapes (same mesh): each true mode with the model mode it resembles
    j = mac(mt.shapes[2::6], ma.shapes[2::6]).argmax(axis=1)
    pairs = data["pairs"]
    assert [p["test_mode"] for p in pairs] == list(range(1, 8))
    assert [p["model_mode"] for p in pairs] == list(j + 1)
    np.testing.assert_allclose([p["f_test_hz"] for p in pairs], mt.frequencies, rtol=5e-6)  # UFF 55: E13.5
    np.testing.assert_allclose([p["f_model_hz"] for p in pairs], ma.frequencies[j], rtol=1e-6)
    df = np.array([p["df_pct"] for p in pairs])
    np.testing.assert_allclose(df, 100 * (ma.frequencies[j] - mt.frequencies) / mt.frequencies, atol=1e-3)
    assert all(p["mac"] > 0.8 for p in pairs)  # the stiffer corner changes the shapes a little
    # a thicker part of the same mass is stiffer: every true frequency is above the model's (df < 0)
    assert np.all(df < 0)
    # and the modes that strain U1 most shift most: fraction of each model mode's strain energy in U1
    K1, _ = assemble(model.model, sets=[n for n in model.model.sets if n.split(".")[:2] == ["components", "U1"]])
    e = np.einsum("ij,ij->j", ma.shapes, K1 @ ma.shapes)[j] / ma.omega2[j]
    shift = -df
    assert np.argmin(shift) == np.argmin(e)
    rank = lambda v: np.argsort(np.argsort(v))  # noqa: E731
    assert np.corrcoef(rank(e), rank(shift))[0, 1] > 0.6
    # Rayleigh bound for the fundamental: bending stiffness of U1 grows by (5/3.5)^3 at most, mass does not drop
    r3 = (5 / 3.5) ** 3
    assert (mt.frequencies[0] / ma.frequencies[j[0]]) ** 2 <= 1 + (r3 - 1) * e[0]


def test_correlate_writes_contract_json_csv_and_pictures(thick):
    d, data, output = thick
    assert {"pairs", "unpaired_test_modes", "comac"} <= set(data)
    for p in data["pairs"]:
        assert {"test_mode", "model_mode", "f_test_hz", "f_model_hz", "df_pct", "mac"} <= set(p)
    assert data["unpaired_test_modes"] == []
    measured = read_uff(d / "thick.uff").modes.dofs
    assert set(data["comac"]) == {f"{i}:+z" for i in measured.point_ids}
    assert all(0 <= v <= 1 + 1e-12 for v in data["comac"].values())
    out = d / "out"
    pngs = ["mac_matrix.png", "frequencies.png", "comac.png"] + [f for f in data["files"] if f.startswith("pair_")]
    assert len(pngs) == 3 + len(data["pairs"])
    for name in pngs:
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = (out / "pairs.csv").read_text().splitlines()
    assert rows[0].startswith("test mode,model mode,f_test [Hz],f_model [Hz],df [%],MAC")
    assert len(rows) == 1 + len(data["pairs"])
    assert float(rows[1].split(",")[4]) == pytest.approx(data["pairs"][0]["df_pct"])
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary files left
    assert "test mode" in output and "COMAC" in output


def _fails(res, *words):
    assert res.exit_code == 2, res.output
    for w in words:
        assert w in res.output, res.output


def test_unreadable_uff_is_a_clear_error_and_writes_nothing(card, tmp_path):
    bad = tmp_path / "bad.uff"
    bad.write_text("this is not a universal file\n")
    res = run("correlate", card / "board.toml", bad, "--out", tmp_path / "out", "--json", tmp_path / "c.json")
    _fails(res, "error:", str(bad))
    assert not (tmp_path / "out").exists() and not (tmp_path / "c.json").exists()


def test_uff_without_modes_names_the_file_and_the_fix(card, tmp_path):
    data = read_uff(card / "noisy.uff")
    write_uff(tmp_path / "frf_only.uff", TestData(data.points, None, data.frfs))
    res = run("correlate", card / "board.toml", tmp_path / "frf_only.uff")
    _fails(res, "frf_only.uff", "no mode shapes", "dataset 55")


def test_points_off_the_board_are_named(card, tmp_path):
    data = read_uff(card / "noisy.uff")
    pts = Points(data.points.ids, data.points.xyz * 1000)  # millimetres written as metres
    data.modes.points = pts
    write_uff(tmp_path / "mm.uff", TestData(pts, data.modes))
    res = run("correlate", card / "board.toml", tmp_path / "mm.uff")
    _fails(res, "mm.uff", "off the board", "board frame")


def test_a_test_in_mm_without_units_is_refused_naming_the_option_and_pairs_with_it(card, tmp_path):
    """The same test written in mm with no dataset 164 (as OROS and Simcenter export): a 162 x 178 "m" grid is
    refused naming --units mm; with --units mm it pairs exactly as the file in metres."""
    data = read_uff(card / "noisy.uff")
    pts = Points(data.points.ids, data.points.xyz * 1000)
    data.modes.points = pts
    write_uff(tmp_path / "mm.uff", TestData(pts, data.modes))
    text = (tmp_path / "mm.uff").read_text()
    start = text.index("    -1\n   164")
    (tmp_path / "mm.uff").write_text(text[:start] + text[text.index("    -1\n", start + 8) + 7:])
    _fails(run("correlate", card / "board.toml", tmp_path / "mm.uff"), "mm.uff", "no dataset 164", "--units mm")
    res = run("correlate", card / "board.toml", tmp_path / "mm.uff", "--units", "mm", "--json", tmp_path / "mm.json")
    assert res.exit_code == 0, res.output
    ref = run("correlate", card / "board.toml", card / "noisy.uff", "--json", tmp_path / "m.json")
    assert ref.exit_code == 0, ref.output
    mm, m = (json.loads((tmp_path / f).read_text()) for f in ("mm.json", "m.json"))
    assert [(p["test_mode"], p["model_mode"]) for p in mm["pairs"]] == [(p["test_mode"], p["model_mode"])
                                                                      for p in m["pairs"]]
    np.testing.assert_allclose([p["mac"] for p in mm["pairs"]], [p["mac"] for p in m["pairs"]], rtol=1e-4)


def test_no_pairs_is_a_clear_error(card, tmp_path):
    # noisy shapes never reach MAC 1, so nothing pairs at --min-mac 1
    res = run("correlate", card / "board.toml", card / "noisy.uff", "--min-mac", 1.0, "--json", tmp_path / "c.json")
    _fails(res, "noisy.uff", "no mode", "--min-mac")
    assert not (tmp_path / "c.json").exists()


def test_simulate_test_rejects_an_excitation_off_the_board(card, tmp_path):
    res = run("simulate-test", card / "board.toml", "--points", POINTS, "--excite", "200,50", "--out",
              tmp_path / "t.uff")
    assert res.exit_code == 2 and "--excite" in res.output and "not on the board" in res.output
    assert not (tmp_path / "t.uff").exists()


def test_simulate_test_names_points_off_the_board(card, tmp_path):
    csv = tmp_path / "pts.csv"
    csv.write_text("point,x [m],y [m]\n1,0.05,0.05\n2,40.5,38.14\n")  # point 2 given in mm under a [m] header
    res = run("simulate-test", card / "board.toml", "--points", csv, "--excite", "135,63.57", "--out",
              tmp_path / "t.uff")
    _fails(res, "pts.csv", "1 point(s) lie off the board", "2 (40500, 38140 mm)")
    assert not (tmp_path / "t.uff").exists()


def test_config_adds_mass_and_lowers_every_frequency(card, tmp_path):
    # configuration c2: 53.2 g at measurement point 6 (thesis 7.3.3); extra mass, same stiffness
    res = run("simulate-test", card / "board.toml", "--config", "c2", "--points", POINTS, "--excite", "135,63.57",
              "--df", 10, "--out", tmp_path / "c2.uff")
    assert res.exit_code == 0, res.output
    res = run("correlate", card / "board.toml", tmp_path / "c2.uff", "--json", tmp_path / "base.json")
    assert res.exit_code == 0, res.output
    res = run("correlate", card / "board.toml", tmp_path / "c2.uff", "--config", "c2", "--json", tmp_path / "c2.json")
    assert res.exit_code == 0, res.output
    base = json.loads((tmp_path / "base.json").read_text())
    same = json.loads((tmp_path / "c2.json").read_text())["pairs"]
    # mass added, stiffness unchanged: the i-th frequency of the loaded card is below the i-th of the bare
    # one (Rayleigh/min-max); the heavy corner mass also mixes shapes, so pairs need not keep the order
    f_loaded = np.sort(base["test_frequencies_hz"])
    assert np.all(f_loaded < np.array(base["model_frequencies_hz"][: f_loaded.size]))
    # the same model up to what UFF 55 keeps (six significant digits)
    assert len(same) == 7 and all(abs(p["df_pct"]) < 1e-3 and p["mac"] > 1 - 1e-9 for p in same)


def test_unknown_configuration_is_named(card):
    res = run("correlate", card / "board.toml", card / "noisy.uff", "--config", "nope")
    _fails(res, "configuration 'nope' does not exist", "c2, c3")


def test_points_on_the_top_surface_read_the_mid_plane(card, tmp_path):
    data = read_uff(card / "noisy.uff")
    top = Points(data.points.ids, data.points.xyz + [0.0, 0.0, 1.4e-3])  # half the 2.8 mm board above z = 0
    data.modes.points = top
    write_uff(tmp_path / "top.uff", TestData(top, data.modes))
    for name in ("noisy", "top"):
        uff = card / "noisy.uff" if name == "noisy" else tmp_path / "top.uff"
        res = run("correlate", card / "board.toml", uff, "--json", tmp_path / f"{name}.json")
        assert res.exit_code == 0, res.output
    a, b = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("noisy", "top"))
    # a flat shell: the offset does not change what is read (the solver repeats to round-off only)
    modes = [[(p["test_mode"], p["model_mode"]) for p in d["pairs"]] for d in (a, b)]
    assert modes[0] == modes[1]
    for key in ("mac", "df_pct"):
        np.testing.assert_allclose([p[key] for p in a["pairs"]], [p[key] for p in b["pairs"]], rtol=1e-9, atol=1e-9)


def test_trace_lines_of_the_test_are_drawn_under_its_points(card, tmp_path):
    """A test file with a trace line (UFF 82, as Test.Lab and ARTeMIS write the test's wireframe) reads it into
    the test's wireframe, and correlate's COMAC map draws it: the picture differs from the one without."""
    data = read_uff(card / "noisy.uff")
    ids = data.points.ids[:4].tolist()
    trace = ("    -1\n    82\n         1         5         8\nedge\n"
             + "".join(f"{i:10d}" for i in ids + [0]) + "\n    -1\n")
    (tmp_path / "traced.uff").write_text((card / "noisy.uff").read_text() + trace)
    assert read_uff(tmp_path / "traced.uff").wireframe.tolist() == sorted(sorted(p) for p in zip(ids[:-1], ids[1:]))
    for name in ("noisy", "traced"):
        src = card / "noisy.uff" if name == "noisy" else tmp_path / "traced.uff"
        res = run("correlate", card / "board.toml", src, "--out", tmp_path / name)
        assert res.exit_code == 0, res.output
    assert (tmp_path / "traced" / "comac.png").read_bytes() != (tmp_path / "noisy" / "comac.png").read_bytes()
    assert (tmp_path / "traced" / "automac.png").stat().st_size > 5000
