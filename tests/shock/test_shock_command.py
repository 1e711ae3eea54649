"""`pcbdyn shock`: the JSON contract, the files, the SRS input's combination, the JEDEC-style
example, and clear errors (exit 2, nothing written) for bad input."""

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from vibe_plates import write_plate

from pcbdyn.cli import main

ROOT = Path(__file__).resolve().parents[2]
PARTS = [("U1", 80.0, 50.0), ("U2", 40.0, 30.0)]


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    return write_plate(tmp_path_factory.mktemp("shock"), 10.0, PARTS)


@pytest.fixture(scope="module")
def pulse_run(plate, tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    js = d / "shock.json"
    res = run("shock", plate, "--pulse", "half-sine 500 g 1 ms", "--damping", "zeta=0.05", "--srs-band", "20,2000",
              "--out", d / "out", "--json", js, "--html")
    assert res.exit_code == 0, res.output
    return d, json.loads(js.read_text()), res.output


def test_json_keeps_the_contract(pulse_run):
    d, data, output = pulse_run
    assert data["input"]["kind"] == "half-sine" and data["input"]["peak"] == pytest.approx(500.0)
    assert data["input"]["duration"] == pytest.approx(1e-3) and data["input"]["combination"] is None
    f = np.array([m["frequency_hz"] for m in data["modes"]])
    assert f[-1] <= 10.0 / 1e-3 and np.all(np.diff(f) > 0)  # modes to ten over the pulse's duration
    for m in data["modes"]:
        assert {"frequency_hz", "damping_ratio", "participation", "effective_mass"} <= set(m)
        assert m["damping_ratio"] == 0.05 and sorted(m["effective_mass"]) == ["rx", "ry", "rz", "x", "y", "z"]
    # the first mode of the simply supported plate carries 64 / pi^4 of its mass in z, as Gamma^2 / m says
    assert data["modes"][0]["effective_mass"]["z"] == pytest.approx(64 / np.pi**4, rel=0.02)
    assert data["effective_mass_fraction"] == pytest.approx(sum(m["effective_mass"]["z"] for m in data["modes"]))
    parts = data["parts"]
    assert [p["ref"] for p in parts] == ["U1", "U2"]  # the centre of a simply supported board first
    for p in parts:
        assert {"ref", "z_peak_m", "curvature_peak_1pm", "z_allow_m", "ratio", "t_peak_s"} <= set(p)
        assert p["ratio"] == pytest.approx(p["z_peak_m"] / p["z_allow_m"]) and p["t_peak_s"] > 0
    srs = data["srs"]
    assert srs["frequency"][0] == 20.0 and srs["frequency"][-1] == pytest.approx(2000, rel=0.03)
    assert len(srs["value"]) == len(srs["frequency"]) and srs["q"] == 10.0
    assert "U1" in output and "z_peak [mm]" in output and "100 in/s" in output


def test_files_are_written(pulse_run):
    d, data, _ = pulse_run
    out = d / "out"
    for name in ("parts.csv", "modes.csv", "srs.csv", "board_map.png", "srs.png", "report.html"):
        assert (out / name).is_file() and (out / name).stat().st_size > 200, name
    assert (out / "modes.csv").read_text().splitlines()[0].count("[%]") == 12  # m_eff and sum, x..rz
    assert 'class="view3d"' in (out / "report.html").read_text()  # the modes in 3-D
    assert sorted(data["files"]) == sorted(p.name for p in out.iterdir() if p.name != "pcbdyn-manifest.json")
    assert "t_z [ms]" in (out / "parts.csv").read_text().splitlines()[0]
    assert (out / "srs.csv").read_text().splitlines()[0] == ("frequency [Hz],srs [g],pseudo velocity [m/s],"
                                                             "pseudo velocity [in/s]")


def test_srs_input_states_its_combination_and_abs_bounds_srss(plate, tmp_path):
    (tmp_path / "spec.csv").write_text("frequency [Hz],acceleration [g]\n100,20\n1000,500\n4000,500\n")
    peaks = {}
    for rule in ("srss", "nrl", "abs"):
        js = tmp_path / f"{rule}.json"
        res = run("shock", plate, "--srs", tmp_path / "spec.csv", "--combine", rule, "--json", js)
        assert res.exit_code == 0, res.output
        data = json.loads(js.read_text())
        assert data["input"]["combination"] == rule and rule.upper() in res.output
        assert data["parts"][0]["t_peak_s"] is None
        peaks[rule] = data["parts"][0]["z_peak_m"]
    assert peaks["srss"] <= peaks["nrl"] <= peaks["abs"]


def test_the_jedec_example_is_symmetric(tmp_path):
    """132 x 77 x 1 mm, 15 parts, four corner standoffs: the parts placed symmetrically about the
    board's centre lines respond alike."""
    js = tmp_path / "jedec.json"
    res = run("shock", ROOT / "examples" / "jedec_drop" / "board.toml", "--pulse", "half-sine 1500 g 0.5 ms",
              "--damping", "zeta=0.05", "--json", js)
    assert res.exit_code == 0, res.output
    data = json.loads(js.read_text())
    z = {p["ref"]: p["z_peak_m"] for p in data["parts"]}
    assert len(z) == 15 and data["parts"][0]["ref"] in ("U3", "U8", "U13")  # the middle column moves most
    for group in (("U1", "U5", "U11", "U15"), ("U2", "U4", "U12", "U14"), ("U6", "U10"), ("U3", "U13")):
        np.testing.assert_allclose([z[r] for r in group], z[group[0]], rtol=0.01)


@pytest.mark.parametrize("args, message", [
    (["--pulse", "half-sine 1500 0.5 ms"], "the peak '1500' has no unit"),
    (["--pulse", "half-sine 1500 g -0.5 ms"], "the duration -0.5 ms must be above 0"),
    (["--srs", "unsorted.csv"], "unsorted.csv: data row 3: frequency 1000 Hz does not rise above the row before"),
    (["--pulse", "half-sine 10 g 1 ms", "--damping", "zeta=2"], "zeta must lie in (0, 1)"),
])
def test_bad_input_is_one_clear_line(plate, tmp_path, args, message):
    (tmp_path / "unsorted.csv").write_text("frequency [Hz],acceleration [g]\n100,10\n2000,1000\n1000,1000\n")
    args = [tmp_path / a if a == "unsorted.csv" else a for a in args]
    res = run("shock", plate, *args, "--out", tmp_path / "out", "--json", tmp_path / "x.json")
    assert res.exit_code == 2 and message in res.output and "Traceback" not in res.output
    assert not (tmp_path / "x.json").exists()
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_a_free_board_is_refused(tmp_path):
    path = tmp_path / "free.toml"
    path.write_text('[board]\nname = "free"\noutline = { width = "100 mm", height = "60 mm" }\nthickness = "1.6 mm"\n'
                    'material = { E = "22 GPa", nu = 0.15, rho = "1850 kg/m^3" }\nmesh_size = "10 mm"\n')
    res = run("shock", path, "--pulse", "half-sine 100 g 1 ms")
    assert res.exit_code == 2 and "free.toml: the model is free" in res.output and "[[fixtures]]" in res.output


def test_exactly_one_input(plate):
    res = run("shock", plate)
    assert res.exit_code == 2 and "give exactly one of --pulse, --history and --srs" in res.output
