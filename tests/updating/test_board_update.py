"""Updating boards from board.toml (issue 5 board-level acceptance): eigenvalue derivatives of board
parameters against re-solves, six-part card thickness recovery from a simulated test, and the
thesis' real measured frequencies (Table 7.2) against its Tables 7.5/7.6."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from pcbdyn.board import build_model, load_board
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata.csvio import read_points_csv
from pcbdyn.testdata.noise import Noise
from pcbdyn.testdata import MeasuredModes
from pcbdyn.testdata.simulate import simulate_on_model
from pcbdyn.problems import UpdateProblem, run
from pcbdyn.updating.sensitivity import eigenvalue_derivatives, pencil_modes

ROOT = Path(__file__).resolve().parents[2]
CARD = ROOT / "examples" / "six_part_card"
from reference import thesis_case
from data_files import board_text
MESH = "13.5 mm"

SPRING_BOARD = board_text("spring_board.toml")


def test_eigenvalue_derivatives_match_resolves(tmp_path):
    """Thesis eq. 3.6 on the board's parameters equals central differences of full re-solves."""
    path = tmp_path / "board.toml"
    path.write_text(SPRING_BOARD)
    prob = UpdateProblem(load_board(path))
    assert [prob.names[i] for i in prob.log_scale] == ["k_guide", "k_s1"]
    sysm = prob.system(None)
    p0 = prob.p0
    n = 6
    lam0 = solve_modes(sysm.at(p0).model, n_modes=n).omega2
    K, M, dKs, dMs = sysm.model(p0)
    lam, Phi = pencil_modes(K, M, n)
    assert np.allclose(lam, lam0, rtol=1e-8)
    dlam = eigenvalue_derivatives(lam, Phi, dKs, dMs)
    for j, name in enumerate(prob.names):
        h = 1e-4 * p0[j]
        up, dn = p0.copy(), p0.copy()
        up[j] += h
        dn[j] -= h
        fd = (solve_modes(sysm.at(up).model, n_modes=n).omega2
              - solve_modes(sysm.at(dn).model, n_modes=n).omega2) / (2 * h)
        scale = np.max(np.abs(lam0)) / p0[j]  # relative to the size of lambda / p
        assert np.max(np.abs(dlam[:, j] - fd)) < 1e-4 * max(np.max(np.abs(fd)), 1e-3 * scale), name


def card(tmp_path, name, thicknesses=None, mesh=MESH) -> Path:
    """The six-part card with one thickness parameter per part (t_U1..t_U6), optionally with given
    part thicknesses [mm]."""
    text = (CARD / "board.toml").read_text().split("[[parameters]]")[0]
    text = re.sub(r'mesh_size = ".*"', f'mesh_size = "{mesh}"', text)
    for i, t in enumerate([] if thicknesses is None else thicknesses):
        text = text.replace(f'ref = "U{i + 1}"\n', f'ref = "U{i + 1}"\nthickness = "{t} mm"\n')
    text += "".join(f'\n[[parameters]]\nname = "t_U{i}"\ntarget = "components.U{i}.thickness"\n'
                    f'bounds = ["2 mm", "10 mm"]\n' for i in range(1, 7))
    path = tmp_path / name
    path.write_text(text)
    return path


def test_six_part_card_qms_recovers_thicknesses(tmp_path):
    """Simulated test of a card with changed part thicknesses (2 % shape, 0.2 % frequency noise,
    z at the 81 grid points), three configurations, QMS: thicknesses within 5 %, frequencies 0.5 %."""
    true_t = np.array([4.2, 3.0, 4.0, 2.9, 3.9, 4.4])
    truth = load_board(card(tmp_path, "true.toml", true_t))
    prob = UpdateProblem(load_board(card(tmp_path, "board.toml")))
    pts, dofs = read_points_csv(CARD / "points.csv")
    cfgs, full = [], []
    for k, c in enumerate([None, "c2", "c3"]):
        bm = build_model(truth, c)
        td = simulate_on_model(bm.model, solve_modes(bm.model, n_modes=7), pts, dofs,
                               noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=k)
        meas = td.modes
        cfgs += prob.mode_configurations(c, meas, "qms")
        full.append(prob.configuration(c, meas, "freq"))  # full model, MAC pairing: the after check
    res, before, after = run(prob, cfgs, "ls", check=full, max_iter=10, tol_freq_pct=0.05)
    assert all(q["mac"] > 0.9 for a in after for q in a["pairs"]) and all(len(a["pairs"]) == 7 for a in after)
    err = res.p / (true_t * 1e-3) - 1
    print("QMS recovered thicknesses [mm]", np.round(res.p * 1e3, 3), "errors %", np.round(100 * err, 2))
    print("max |df| after:", [round(a["max_freq_error_pct"], 3) for a in after])
    assert np.max(np.abs(err)) < 0.05
    assert max(a["max_freq_error_pct"] for a in after) < 0.5


def thesis_table_7_5_rf():
    """The thesis' frequencies of configuration 1 after its RF-based update (Table 7.5), as
    re-constructed in the reference file (f_x (1 - residue))."""
    case = thesis_case("T7.5_real_pcb_updated_thicknesses")
    return np.asarray(case["ours_primary"]["RF"]["thesis_Hz"], float)


def measured(select):
    import pandas as pd

    df = pd.read_csv(CARD / "measured_frequencies_table_7_2.csv", comment="#")
    out = []
    for cfg, modes in select.items():
        g = df[(df.configuration == cfg) & df["mode"].isin(modes)]
        out.append((None if cfg == "c1" else cfg,
                    MeasuredModes.frequencies_only(g.frequency_hz.to_numpy(float), g["mode"].to_numpy(int))))
    return out


@pytest.mark.parametrize("select,solver", [
    ({"c1": range(1, 7)}, "bayes"),  # as Table 7.5: 6 equations for 6 unknowns, rank 5: Bayesian step
    ({"c1": range(1, 7), "c2": range(1, 4), "c3": range(1, 7)}, "bounded"),  # as Table 7.6 (modes pairable by order)
])
def test_real_card_frequency_updating(tmp_path, select, solver):
    """Measured frequencies of the real card (Table 7.2), six thicknesses, frequency-based
    updating (configuration 1 alone: Bayesian step with line search, eqs. 4.38-4.40, 7.5-7.6; three
    configurations: bounded least squares, eqs. 4.44-4.48): the error drops, stays physical (within [2, 10] mm) and ends below 5 %."""
    prob = UpdateProblem(load_board(card(tmp_path, "board.toml")))
    cfgs = [prob.configuration(c, m, "freq") for c, m in measured(select)]
    res, before, after = run(prob, cfgs, solver, max_iter=15, tol_freq_pct=0.1)
    b1, a1 = before[0], after[0]
    print(f"\nconfigurations {list(select)}: {res.reason}")
    thesis = thesis_table_7_5_rf()
    print(f"{'mode':>4} {'f_x':>8} {'ours 1-fa/fx [%]':>17} {'thesis T7.5 RF [%]':>19}")
    for q in a1["pairs"]:
        fx = q["f_test_hz"]
        print(f"{q['test_mode']:>4} {fx:>8.2f} {-q['df_pct']:>17.2f} {100 * (1 - thesis[q['test_mode'] - 1] / fx):>19.2f}")
    print("thicknesses [mm]:", np.round(res.p * 1e3, 2), "| max |df| per config before",
          [round(s["max_freq_error_pct"], 2) for s in before], "after", [round(s["max_freq_error_pct"], 2) for s in after])
    assert np.all(res.p >= 2e-3 - 1e-12) and np.all(res.p <= 10e-3 + 1e-12)
    assert a1["max_freq_error_pct"] < b1["max_freq_error_pct"]
    assert max(s["max_freq_error_pct"] for s in after) < 5.0


def test_update_command_writes_board_and_json(tmp_path):
    """The CLI on the measured frequencies: updated board next to the original, JSON with the values."""
    from click.testing import CliRunner

    from pcbdyn.cli import main

    path = card(tmp_path, "board.toml")
    js = tmp_path / "u.json"
    r = CliRunner().invoke(main, ["update", str(path), "--frequencies", str(CARD / "measured_frequencies_table_7_2.csv"),
                                  "--params", "t_U1,t_U2,t_U3,t_U4,t_U5,t_U6", "--max-iter", "3", "--json", str(js),
                                  "--out", str(tmp_path / "out"), "--force", "--no-mesh-check"])
    assert r.exit_code == 0, r.output
    data = json.loads(js.read_text())
    assert data["updated_board"] == str(tmp_path / "out" / "board.updated.toml")
    updated = load_board(data["updated_board"])
    for i in range(1, 7):
        assert updated.component(f"U{i}").thickness == pytest.approx(data["parameters"][f"t_U{i}"]["updated"], rel=1e-12)
    assert (tmp_path / "out" / "iterations.png").exists()
    assert data["after"]["max_freq_error_pct"] <= data["before"]["max_freq_error_pct"]
    assert data["status"] in ("converged", "not converged", "on a bound", "not determined", "error grew", "cannot fit")


def test_update_command_qms_from_uff(tmp_path):
    """End to end: simulated UFF tests of two configurations (noise-free shapes and frequencies) of a
    card with two changed part thicknesses, on the model's own mesh (so no mesh check: there is no mesh error
    to take out); `pcbdyn update --method qms` recovers them."""
    from click.testing import CliRunner

    from pcbdyn.cli import main
    from pcbdyn.testdata.uff import write_uff

    true_t = np.array([4.2, 3.5, 3.5, 2.9, 3.5, 3.5])
    truth = load_board(card(tmp_path, "true.toml", true_t))
    pts, dofs = read_points_csv(CARD / "points.csv")
    files = []
    for k, c in enumerate([None, "c2"]):
        bm = build_model(truth, c)
        td = simulate_on_model(bm.model, solve_modes(bm.model, n_modes=6), pts, dofs)
        files.append(tmp_path / f"test{k}.uff")
        write_uff(files[-1], td)
    path = card(tmp_path, "board.toml")
    js = tmp_path / "u.json"
    r = CliRunner().invoke(main, ["update", str(path), str(files[0]), f"c2={files[1]}", "--method", "qms",
                                  "--solver", "ls", "--params", "t_U1,t_U4", "--json", str(js), "--no-mesh-check"])
    assert r.exit_code == 0, r.output
    data = json.loads(js.read_text())
    assert data["parameters"]["t_U1"]["unit"] == "m"
    got = [data["parameters"][n]["updated"] for n in ("t_U1", "t_U4")]
    assert got == pytest.approx([4.2e-3, 2.9e-3], rel=0.01)
    assert data["after"]["max_freq_error_pct"] < 0.1
