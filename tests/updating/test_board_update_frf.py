"""`pcbdyn update --method frf-in/frf-out/frf-direct` on FRFs read from UFF (issue 5): simulated
driving-point tests of the six-part card with two changed part thicknesses, two configurations,
updating frequencies chosen automatically (FDAC away from the resonances)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.board import build_model, load_board
from pcbdyn.cli import main
from pcbdyn.fe.modal import solve_modes as fe_modes
from pcbdyn.testdata.csvio import read_points_csv
from pcbdyn.testdata.simulate import simulate_on_model
from pcbdyn.testdata.uff import write_uff
from test_board_update import CARD, card

TRUE_T = np.array([4.2, 3.5, 3.5, 2.9, 3.5, 3.5])
SHAKER = (0.135, 0.06357, 0.0)  # the force transducer's node
F_AXIS = np.arange(0.0, 1200.0, 2.0)


@pytest.fixture(scope="module")
def tests(tmp_path_factory):
    """{zeta: (base UFF, c2 UFF)}: accelerances of the true card (20 modes, modal damping zeta) at
    the 81 grid points and the shaker, with the modes (dataset 55)."""
    tmp = tmp_path_factory.mktemp("frf")
    truth = load_board(card(tmp, "true.toml", TRUE_T))
    pts, dofs = read_points_csv(CARD / "points.csv")
    out = {}
    for zeta in (0.0, 0.01):
        files = []
        for c in (None, "c2"):
            bm = build_model(truth, c)
            td = simulate_on_model(bm.model, fe_modes(bm.model, n_modes=20), pts, dofs, excite=SHAKER, f_axis=F_AXIS,
                                   zeta=zeta, kind="accelerance")
            files.append(tmp / f"{c or 'base'}_{zeta}.uff")
            write_uff(files[-1], td)
        out[zeta] = files
    return out


def update(tmp_path, files, *options):
    js = tmp_path / "u.json"
    r = CliRunner().invoke(main, ["update", str(card(tmp_path, "board.toml")), str(files[0]), f"c2={files[1]}",
                                  "--solver", "ls", "--params", "t_U1,t_U4", "--json", str(js), *options])
    return r, js


@pytest.mark.parametrize("zeta,options", [
    (0.0, ["--method", "frf-out"]),  # eq. 3.35
    (0.0, ["--method", "frf-in"]),  # eq. 3.34, condensed exactly at each line
    (0.01, ["--method", "frf-in", "--damping", "diagonal"]),  # eqs. A.7-A.13 on 1 % modal damping
    (0.01, ["--method", "frf-direct"]),  # eq. 3.40
])
def test_frf_methods_recover_part_thicknesses(tmp_path, tests, zeta, options):
    """The two changed thicknesses come back within 1.5 % (the data hold 20 modes, the model all:
    truncation is the only error) and the paired frequencies of both configurations within 0.2 %;
    the automatic updating lines keep clear of every measured resonance (10 % from those the
    excitation shows, 5 % from any)."""
    r, js = update(tmp_path, tests[zeta], *options)
    assert r.exit_code == 0, r.output
    data = json.loads(js.read_text())
    got = np.array([data["parameters"][n]["updated"] for n in ("t_U1", "t_U4")])
    print(options, zeta, "thicknesses [mm]", np.round(got * 1e3, 4), data["reason"])
    assert got == pytest.approx(TRUE_T[[0, 3]] * 1e-3, rel=0.015)
    assert data["before"]["max_freq_error_pct"] > 2.0 and data["after"]["max_freq_error_pct"] < 0.2
    lines = [[float(v) for v in m.split("frequencies")[1].replace("Hz", "").split(",")]
             for m in r.output.splitlines() if "updating frequencies" in m]
    assert [len(v) for v in lines] >= [4, 4]
    for chosen, cfg in zip(lines, data["before"]["configurations"]):
        f_test = np.array([q["f_test_hz"] for q in cfg["pairs"]])
        assert all(np.min(np.abs(f / f_test - 1)) > 0.05 for f in chosen), (chosen, f_test)

def test_frf_freqs_given_and_checked(tmp_path, tests):
    """--frf-freqs uses the nearest measured lines; a frequency outside the measured band and a UFF
    without FRFs are refused, naming the option or the file and the fix."""
    r, js = update(tmp_path, tests[0.0], "--method", "frf-out", "--frf-freqs", "250,436,709")
    assert r.exit_code == 0, r.output
    assert "updating frequencies 250.0, 436.0, 708.0 Hz" in r.output
    r, _ = update(tmp_path, tests[0.0], "--method", "frf-out", "--frf-freqs", "250,5000")
    assert r.exit_code != 0 and "--frf-freqs" in r.output and "1198" in r.output
    modes_only = tmp_path / "modes.uff"
    truth = build_model(load_board(card(tmp_path, "true.toml", TRUE_T)))
    pts, dofs = read_points_csv(CARD / "points.csv")
    write_uff(modes_only, simulate_on_model(truth.model, fe_modes(truth.model, n_modes=6), pts, dofs))
    r, _ = update(tmp_path, [modes_only, tests[0.0][1]], "--method", "frf-in")
    assert r.exit_code != 0 and "modes.uff" in r.output and "no FRFs" in r.output
