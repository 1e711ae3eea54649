"""`pcbdyn vibe`: the JSON contract, the files, damping options (a UFF's identified damping
included) and clear errors for bad input."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from vibe_plates import A, B, write_plate

from pcbdyn.cli import main
from pcbdyn.vibration.spectra import G

PARTS = [("U1", 80.0, 50.0), ("U2", 40.0, 30.0)]


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    return write_plate(tmp_path_factory.mktemp("vibe"), 10.0, PARTS)


@pytest.fixture(scope="module")
def full_run(plate, tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    (d / "sweep.csv").write_text("frequency [Hz],amplitude [g]\n20,1\n2000,1\n")
    js = d / "vibe.json"
    res = run("vibe", plate, "--psd", "gevs-qual", "--sine", d / "sweep.csv", "--chassis-freq", "100 Hz",
              "--out", d / "out", "--json", js, "--html")
    assert res.exit_code == 0, res.output
    return d, json.loads(js.read_text()), res.output


def test_json_keeps_the_contract_and_the_physics(full_run):
    d, data, output = full_run
    assert data["input_grms"] == pytest.approx(14.14, abs=0.01)  # GEVS qualification
    f = np.array([m["frequency_hz"] for m in data["modes"]])
    zeta = np.array([m["damping_ratio"] for m in data["modes"]])
    np.testing.assert_allclose(zeta, 0.5 / np.sqrt(f))  # Steinberg's Q = sqrt(f_n) by default
    assert f[-1] <= 4000.0 and np.all(np.diff(f) > 0)  # every mode up to twice the top of the PSD
    parts = data["parts"]
    assert {p["ref"] for p in parts} == {"U1", "U2"}
    for p in parts:
        assert {"ref", "z_rms_m", "z_allow_m", "ratio", "life_h"} <= set(p)
        assert p["ratio"] == pytest.approx(3 * p["z_rms_m"] / p["z_allow_m"])
        assert p["life_h"] > 0 and p["sine_damage"] > 0 and p["damage"] > 0
    assert [p["margin"] for p in parts] == sorted(p["margin"] for p in parts)  # worst first
    assert parts[0]["ref"] == "U1"  # the centre of a simply supported board moves most
    assert data["duration_s"] == 120.0  # GEVS qualification: 2 min per axis
    assert data["octave_rule"]["ok"] is True and data["octave_rule"]["ratio"] == pytest.approx(f[0] / 100.0)
    assert "U1" in output and "z_allow [mm]" in output and "octave rule" in output


def test_files_are_written(full_run):
    d, data, _ = full_run
    out = d / "out"
    for name in ("parts.csv", "modes.csv", "response_psd.csv", "board_map.png", "response_psd.png", "report.html"):
        assert (out / name).is_file() and (out / name).stat().st_size > 200, name
    assert sorted(data["files"]) == sorted(p.name for p in out.iterdir() if p.name != "pcbdyn-manifest.json")
    head = (out / "parts.csv").read_text().splitlines()[0]
    assert "z_rms [mm]" in head and "life [h]" in head and "sine damage" in head
    spectra = (out / "response_psd.csv").read_text().splitlines()[0]
    assert "U1 acceleration [g^2/Hz]" in spectra and "U1 relative displacement [mm^2/Hz]" in spectra
    assert not list(out.glob(".*"))  # nothing half-written left behind


def test_a_spectrum_below_the_fundamental_is_judged(plate, tmp_path):
    """20-100 Hz under a 350 Hz fundamental: no mode lies in the analysis band (twice the top); the
    first modes are solved all the same and the board follows the base quasi-statically (it was an
    internal error)."""
    (tmp_path / "low.csv").write_text("frequency [Hz],psd [g^2/Hz]\n20,0.04\n100,0.04\n")
    js = tmp_path / "low.json"
    res = run("vibe", plate, "--psd", tmp_path / "low.csv", "--json", js)
    assert res.exit_code == 0, res.output
    data = json.loads(js.read_text())
    assert len(data["modes"]) == 3 and data["modes"][0]["frequency_hz"] > 300.0
    # at the centre the (1, 1) mode (phi Gamma = 16 / pi^2) carries the board below resonance:
    # |1 + c r^2 / (1 - r^2 + 2 i zeta r)|, r = f / f1, integrated over the flat band
    f1 = data["modes"][0]["frequency_hz"]
    f = np.linspace(20.0, 100.0, 2001)
    r, zeta = f / f1, data["modes"][0]["damping_ratio"]
    t2 = np.abs(1 + 16 / np.pi**2 * r**2 / (1 - r**2 + 2j * zeta * r)) ** 2
    expected = np.sqrt(0.04 * np.trapezoid(t2, f))
    centre = next(p for p in data["parts"] if p["ref"] == "U1")
    assert centre["accel_rms_g"] == pytest.approx(expected, rel=0.01)


def test_more_damping_less_response(plate, tmp_path):
    out = {}
    for damping in ("zeta=0.02", "Q=25"):  # Q = 25 is zeta = 0.02: the same run
        js = tmp_path / f"{damping}.json"
        assert run("vibe", plate, "--psd", "gevs-accept", "--damping", damping, "--json", js).exit_code == 0
        out[damping] = json.loads(js.read_text())
    js = tmp_path / "z05.json"
    assert run("vibe", plate, "--psd", "gevs-accept", "--damping", "zeta=0.05", "--json", js).exit_code == 0
    z05 = json.loads(js.read_text())
    a, b = (out[k]["parts"][0]["z_rms_m"] for k in ("zeta=0.02", "Q=25"))
    assert a == pytest.approx(b, rel=1e-12)
    # one dominant mode: z_rms ~ 1/sqrt(zeta)
    assert z05["parts"][0]["z_rms_m"] == pytest.approx(a * np.sqrt(0.02 / 0.05), rel=0.03)


def test_damping_identified_in_a_uff_goes_to_the_paired_modes(plate, tmp_path):
    pts = tmp_path / "points.csv"
    xs, ys = np.meshgrid(np.linspace(10, A * 1e3 - 10, 7), np.linspace(10, B * 1e3 - 10, 5))
    pts.write_text("point,x [mm],y [mm]\n" + "".join(f"{i + 1},{x:g},{y:g}\n" for i, (x, y) in
                                                       enumerate(zip(xs.ravel(), ys.ravel()))))
    uff = tmp_path / "test.uff"
    res = run("simulate-test", plate, "--points", pts, "--excite", "30,20", "--damping", 0.025, "--modes", 4,
              "--out", uff)
    assert res.exit_code == 0, res.output
    js = tmp_path / "v.json"
    res = run("vibe", plate, "--psd", "gevs-workmanship", "--damping", uff, "--json", js)
    assert res.exit_code == 0, res.output
    modes = json.loads(js.read_text())["modes"]
    for m in modes[:4]:
        assert m["damping_ratio"] == pytest.approx(0.025) and m["damping_source"].startswith("test mode")
    for m in modes[4:]:
        assert m["damping_ratio"] == pytest.approx(0.5 / np.sqrt(m["frequency_hz"]))


def test_a_csv_psd_in_si_units_gives_the_named_levels(plate, tmp_path):
    spec = tmp_path / "gevs.csv"
    spec.write_text("frequency [Hz],psd [(m/s^2)^2/Hz]\n" + "".join(
        f"{f},{w * G**2!r}\n" for f, w in ((20, 0.026), (50, 0.16), (800, 0.16), (2000, 0.026))))
    js1, js2 = tmp_path / "a.json", tmp_path / "b.json"
    assert run("vibe", plate, "--psd", spec, "--json", js1).exit_code == 0
    assert run("vibe", plate, "--psd", "gevs-qual", "--json", js2).exit_code == 0
    a, b = (json.loads(p.read_text()) for p in (js1, js2))
    assert a["parts"][0]["z_rms_m"] == pytest.approx(b["parts"][0]["z_rms_m"], rel=1e-9)
    assert a["duration_s"] is None and a["parts"][0]["damage"] is None  # a CSV states no duration


def bad(tmp_path, *args):
    res = run("vibe", *args)
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output
    return res.output


def test_bad_input_gets_clear_errors(plate, tmp_path):
    unsorted = tmp_path / "unsorted.csv"
    unsorted.write_text("frequency [Hz],psd [g^2/Hz]\n20,0.01\n2000,0.01\n100,0.04\n")
    assert "unsorted.csv: data row 3: frequency 100 Hz does not rise above the row before (2000 Hz)" in \
        bad(tmp_path, plate, "--psd", unsorted)
    negative = tmp_path / "negative.csv"
    negative.write_text("frequency [Hz],psd [g^2/Hz]\n20,0.01\n2000,-0.01\n")
    assert "negative.csv: data row 2: PSD value -0.01 g^2/Hz at 2000 Hz must be above 0" in \
        bad(tmp_path, plate, "--psd", negative)
    no_unit = tmp_path / "no_unit.csv"
    no_unit.write_text("frequency,psd [g^2/Hz]\n20,0.01\n2000,0.01\n")
    assert "no_unit.csv: column 'frequency' has no unit; write it as 'frequency [Hz]'" in \
        bad(tmp_path, plate, "--psd", no_unit)
    assert "--damping 'zeta=2'" in bad(tmp_path, plate, "--psd", "gevs-qual", "--damping", "zeta=2")
    assert "--exclude U9: no such part" in bad(tmp_path, plate, "--psd", "gevs-qual", "--exclude", "U9")
    assert "--duration: cannot read 'two minutes' as a quantity" in \
        bad(tmp_path, plate, "--psd", "gevs-qual", "--duration", "two minutes")


def test_a_part_without_a_package_constant_is_named(tmp_path):
    extra = ('[[components]]\nref = "J1"\nat = ["120 mm", "50 mm"]\nsize = ["20 mm", "8 mm"]\nmass = "5 g"\n'
             'model = "lumped"\n')
    board = write_plate(tmp_path, 10.0, PARTS, extra)
    msg = bad(tmp_path, board, "--psd", "gevs-qual")
    assert "board.toml: no Steinberg package constant for J1 (no library package)" in msg
    assert "steinberg_c" in msg and "--exclude J1" in msg
    assert run("vibe", board, "--psd", "gevs-qual", "--exclude", "J1").exit_code == 0


def test_a_free_board_is_refused(tmp_path):
    free = tmp_path / "free.toml"
    free.write_text('[board]\nname = "free"\noutline = { width = "100 mm", height = "80 mm" }\nthickness = "1.6 mm"\n'
                    'material = { E = "22 GPa", nu = 0.15, rho = "1850 kg/m^3" }\nmesh_size = "20 mm"\n')
    msg = bad(tmp_path, free, "--psd", "gevs-qual")
    assert "error: free.toml: the model is free (no fixture holds it)" in msg and "[[fixtures]]" in msg


def test_html_needs_out(plate, tmp_path):
    res = run("vibe", plate, "--psd", "gevs-qual", "--html")
    assert res.exit_code == 2 and "--html writes report.html into --out" in res.output


def test_effective_masses_and_the_warning_when_the_modes_carry_too_little(full_run, plate, tmp_path):
    """modes[].effective_mass holds fractions in x, y, z, rx, ry, rz; the first mode of a simply supported
    plate carries 64 / pi^4 of its mass in z ((mean sin)^4 / mean sin^2 squared); their sum along the shaken
    axis is effective_mass_fraction, and vibe warns when it is below 90 %. Shaken along x, the bending modes
    of a flat board move none of its mass: warned."""
    _, data, output = full_run
    em = [m["effective_mass"] for m in data["modes"]]
    assert all(sorted(e) == ["rx", "ry", "rz", "x", "y", "z"] for e in em)
    assert em[0]["z"] == pytest.approx(64 / np.pi**4, rel=0.02)
    share = data["effective_mass_fraction"]
    assert share == pytest.approx(sum(e["z"] for e in em), rel=1e-12) and 0.8 < share < 1.0
    warned = [n for n in data["notes"] if "of the mass moved along z (< 90 %)" in n]
    assert bool(warned) == (share < 0.9), (share, data["notes"])
    assert f"{100 * share:.2f} % of the mass moved along z" in output
    js = tmp_path / "x.json"
    assert run("vibe", plate, "--psd", "gevs-qual", "--axis", "x", "--json", js).exit_code == 0
    x = json.loads(js.read_text())
    assert x["effective_mass_fraction"] < 1e-6
    assert any("of the mass moved along x (< 90 %)" in n for n in x["notes"]), x["notes"]
