"""`pcbdyn identify`: modes from FRFs simulated on the six-part card with 1 % noise on every FRF
value, against the model's own modes (frequencies, damping 1 %, shapes)."""

import json
from pathlib import Path

import numpy as np
import pyuff
import pytest
from click.testing import CliRunner
from data_files import realdata

from pcbdyn.board import build_model, load_board
from pcbdyn.cli import main
from pcbdyn.correlation import mac
from pcbdyn.fe.modal import solve_modes
from pcbdyn.identification import identify
from pcbdyn.testdata import FRFs, Dofs, Noise, Points, TestData, read_points_csv, read_uff, write_uff
from pcbdyn.testdata.simulate import simulate_on_model

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"
BAND = (100.0, 1300.0)
ZETA = 0.01


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    """FRFs (accelerance, 1 Hz lines to 1400 Hz, excited at point 34, a driving point) with 1 % noise
    on every FRF value; the noise-free modes in the same file are the truth."""
    d = tmp_path_factory.mktemp("identify")
    res = run("simulate-test", EXAMPLE / "board.toml", "--points", EXAMPLE / "points.csv", "--excite", "135,63.57",
              "--noise", "frf=1", "--seed", 7, "--modes", 12, "--f-range", "0,1400", "--damping", ZETA,
              "--out", d / "frfs.uff", "--json", d / "sim.json")
    assert res.exit_code == 0, res.output
    truth = read_uff(d / "frfs.uff").modes
    return d, truth


def check_against_truth(modes, truth, band):
    inside = (truth.frequencies >= band[0]) & (truth.frequencies <= band[1])
    f_true = truth.frequencies[inside]
    assert modes.n_modes == f_true.size
    np.testing.assert_allclose(modes.frequencies, f_true, rtol=0.002)
    np.testing.assert_allclose(modes.damping, ZETA, rtol=0.10)
    M = np.diag(mac(modes.shapes, truth.shapes[:, inside]))
    assert M.min() > 0.98, M
    return M


def test_identify_recovers_every_mode_of_the_band(sim):
    d, truth = sim
    res = run("identify", d / "frfs.uff", "--band", "100,1300Hz", "--out", d / "modes.uff", "--json", d / "id.json")
    assert res.exit_code == 0, res.output
    modes = read_uff(d / "modes.uff").modes  # UFF 55 with damping: what correlate reads
    M = check_against_truth(modes, truth, BAND)
    data = json.loads((d / "id.json").read_text())
    # the UFF keeps what dataset 55's standard E13.5 fields hold: six significant digits
    assert [m["frequency_hz"] for m in data["modes"]] == pytest.approx(modes.frequencies.tolist(), rel=5e-6)
    assert [m["damping_ratio"] for m in data["modes"]] == pytest.approx(modes.damping.tolist(), rel=5e-6)
    neighbours = [m["mac_neighbours"] for m in data["modes"]]
    assert neighbours[0]["previous"] is None and neighbours[-1]["next"] is None
    assert max(n["next"] for n in neighbours[:-1]) < 0.5  # distinct shapes
    assert data["scaling"] == "mass" and data["selection"] == "auto"
    assert data["criteria"]["shape_test"] == "MAC of the residues over all FRFs" and data["notes"] == []
    assert np.median([m["mpc"] for m in data["modes"]]) > 0.9999  # real simulated modes: collinear ...
    for m, f in zip(data["modes"], modes.frequencies):  # ... up to the noise, and each a steady column
        assert m["mpc"] > 0.95 and m["mpd_deg"] < 10.0 and m["complexity"] == pytest.approx(1 - m["mpc"])
        assert m["poles"] >= 3 and m["frequency_std_hz"] < 0.002 * f and abs(m["frequency_mean_hz"] / f - 1) < 0.002
    # mass-normalised at the driving point: the modal scale of the well-fitted modes is the truth's
    inside = (truth.frequencies >= BAND[0]) & (truth.frequencies <= BAND[1])
    scale = np.einsum("ij,ij->j", modes.shapes, truth.shapes[:, inside]) / np.sum(truth.shapes[:, inside] ** 2, axis=0)
    assert np.median(np.abs(scale[M > 0.999])) == pytest.approx(1.0, abs=0.03)
    assert (d / "modes.stabilisation.png").stat().st_size > 10_000


def test_mode_free_band_reports_none(sim):
    d, truth = sim
    assert not np.any((truth.frequencies > 600) & (truth.frequencies < 760))
    res = run("identify", d / "frfs.uff", "--band", "600,760", "--out", d / "none.uff", "--json", d / "none.json")
    assert res.exit_code == 0, res.output
    assert json.loads((d / "none.json").read_text())["modes"] == []
    assert "no mode identified" in res.output
    assert read_uff(d / "none.uff").modes is None


def test_several_references_and_manual_choice(sim):
    """FRFs of two driving points in one set (one LSCF denominator, residues over both columns)."""
    _, truth = sim
    bm = build_model(load_board(EXAMPLE / "board.toml"))
    model_modes = solve_modes(bm.model, 12)
    points, dofs = read_points_csv(EXAMPLE / "points.csv")
    f_axis = np.arange(0.0, 1401.0)
    tests = [simulate_on_model(bm.model, model_modes, points, dofs, excite=(x, y, 0.0), f_axis=f_axis, zeta=ZETA,
                               noise=Noise(frf_pct=1.0), seed=s, tol=0.02)
             for s, (x, y) in enumerate([(0.135, 0.06357), (0.0405, 0.16529)])]
    refs = Dofs([t.frfs.reference.point_ids[0] for t in tests], (0.0, 0.0, 1.0))
    frfs = FRFs(points, f_axis, np.concatenate([t.frfs.H for t in tests], axis=2), "accelerance", dofs, refs)
    result = identify(frfs, BAND, 40)
    assert result.scaling == "mass"
    check_against_truth(result.modes, truth, BAND)
    picked = identify(frfs, BAND, 40, select=[198.0, 531.0, 985.0])
    assert picked.selection == "manual" and picked.notes == []
    np.testing.assert_allclose(picked.modes.frequencies, truth.frequencies[[0, 4, 7]], rtol=0.002)
    shared = identify(frfs, BAND, 40, select=[198.0, 199.0, 531.0])  # two requests, one column: kept once, said
    np.testing.assert_allclose(shared.modes.frequencies, truth.frequencies[[0, 4]], rtol=0.002)
    assert len(shared.notes) == 1 and "199 Hz and 198 Hz pick the same pole" in shared.notes[0]


def test_bad_frf_files_get_clear_errors(sim, tmp_path):
    d, truth = sim
    f = np.arange(0.0, 500.0)
    no_ref = tmp_path / "no_reference.uff"
    pyuff.UFF(str(no_ref)).write_sets([{
        "type": 58, "func_type": 4, "rsp_node": 1, "rsp_dir": 3, "ref_node": 0, "ref_dir": 0, "x": f,
        "data": np.ones(f.size, complex), "abscissa_spacing": 1, "ordinate_spec_data_type": 12,
        "orddenom_spec_data_type": 13, "id1": "FRF without reference"}], mode="overwrite")
    res = run("identify", no_ref, "--out", tmp_path / "a.uff")
    assert res.exit_code == 2 and "no_reference.uff" in res.output and "names no reference" in res.output
    write_uff(tmp_path / "modes_only.uff", TestData(truth.points, truth))
    res = run("identify", tmp_path / "modes_only.uff", "--out", tmp_path / "b.uff")
    assert res.exit_code == 2 and "no FRFs" in res.output
    res = run("identify", d / "frfs.uff", "--band", "5000,6000", "--out", tmp_path / "c.uff")
    assert res.exit_code == 2 and "5000-6000 Hz" in res.output
    res = run("identify", d / "frfs.uff", "--select", "198,abc", "--out", tmp_path / "d.uff")
    assert res.exit_code == 2 and "--select" in res.output
    assert "Traceback" not in res.output
    assert not any((tmp_path / n).exists() for n in ("a.uff", "b.uff", "c.uff", "d.uff"))


PYUFF, realdata_only = realdata("pyuff")
#: free-free Euler-Bernoulli beam: beta_n L of the first six bending modes (f_n ~ (beta_n L)^2; Blevins,
#: Formulas for natural frequency and mode shape, table 8-1)
BETA_L = np.array([4.73004, 7.85320, 10.99561, 14.13717, 17.27876, 20.42035])


@realdata_only
def test_identify_measured_beam_accelerances_without_geometry(tmp_path):
    """pyuff's measured accelerances (a free beam struck at 3 points, read at point 1; 1 Hz lines; no geometry):
    refused without points, naming --points; with them the automatic choice finds 6 modes in 20-1000 Hz
    whose frequency ratios are the free-free beam's (beta_n L)^2 ratios within 1 %."""
    uff = PYUFF / "measurement_e2089be.uff"
    res = run("identify", uff, "--band", "20,1000", "--out", tmp_path / "m.uff")
    assert res.exit_code == 2 and "--points" in res.stderr and "Traceback" not in res.output
    (tmp_path / "points.csv").write_text("point,x [mm],y [mm],z [mm]\n1,0,0,0\n2,100,0,0\n3,200,0,0\n")
    res = run("identify", uff, "--band", "20,1000", "--points", tmp_path / "points.csv", "--out", tmp_path / "m.uff",
              "--json", tmp_path / "m.json")
    assert res.exit_code == 0, res.output
    f = np.array([m["frequency_hz"] for m in json.loads((tmp_path / "m.json").read_text())["modes"]])
    np.testing.assert_allclose(f / f[0], BETA_L**2 / BETA_L[0] ** 2, rtol=0.01)


@realdata_only
@pytest.mark.parametrize("ref", [0, 1, 2])
def test_identify_one_measured_frf_alone_finds_the_beam_modes(ref):
    """Each of the three measured FRFs alone (single reference, single response, where the shape test cannot
    fail): every bending mode of the three-FRF identification is found within 0.2 %; one more pole column,
    at 900 Hz in the third FRF (a small resonance there only), is the most the choice adds."""
    data = read_uff(PYUFF / "measurement_e2089be.uff", points=Points([1, 2, 3], np.zeros((3, 3))))
    every = identify(data.frfs, (20.0, 1000.0), 40).modes.frequencies
    one = FRFs(data.frfs.points, data.frfs.frequencies, data.frfs.H[:, :, ref:ref + 1], data.frfs.kind,
               data.frfs.response, data.frfs.reference.take([ref]))
    alone = identify(one, (20.0, 1000.0), 40)
    near = np.abs(alone.modes.frequencies[None, :] / every[:, None] - 1)
    assert every.size == 6 and near.min(axis=1).max() < 0.002
    assert alone.modes.n_modes - every.size <= 1 and alone.criteria["shape_test"] == "none: one FRF"
