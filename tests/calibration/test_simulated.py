"""Acceptance on simulated data (issue 19): three boards of different layouts carry PGA, CQFP and JLCC
parts whose true equivalent thicknesses scatter 3 % part to part around family means the library does
not know (it says 3.5 mm for all); their tests come from pcbdyn's own truth meshed twice as fine with
2 % shape and 0.2 % frequency noise. Calibrated from all three (one run per board pooled by the
library, and one joint stacked run), each family value lies within 5 % of its true mean and within 3
reported standard deviations, and a fourth, unseen board built with the calibrated library is
predicted within 1.5 % on every mode below 1 kHz, where the uncalibrated library misses by several
percent."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.board import load_board
from pcbdyn.cli import main
from pcbdyn.components.library import chosen
from pcbdyn.correlation.mac import mac
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import model_probe
from pcbdyn.problems.uncertainty import frequency_std, library_uncertainty

from sim_boards import TRUE_MM, grid, write_case

BOARDS = ["b1", "b2", "b3"]


def calibrate(args, js):
    r = CliRunner().invoke(main, ["calibrate", *map(str, args), "--json", str(js)])
    assert r.exit_code == 0, r.output
    return json.loads(js.read_text()), r.output


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    d = tmp_path_factory.mktemp("sim")
    out = {name: write_case(d, name, seed=k) for k, name in enumerate(BOARDS + ["b4"])}
    return d, out


def check_families(families, label):
    print(f"\n{label}: family   true mean   calibrated (library)   error   z")
    for fam, d in families.items():
        v, sd, true = d["equivalent_thickness_m"] * 1e3, d["std_m"] * 1e3, TRUE_MM[fam]
        print(f"  {fam:>5} {true:>10.3f} {v:>12.3f} +- {sd:.3f} mm {100 * (v / true - 1):+7.2f} % {(v - true) / sd:+6.2f}")
    for fam, d in families.items():
        v, sd, true = d["equivalent_thickness_m"] * 1e3, d["std_m"] * 1e3, TRUE_MM[fam]
        assert abs(v / true - 1) < 0.05, fam
        assert abs(v - true) < 3 * sd, fam


def predict_unseen(d, board, lib, label):
    """Max |f_model / f_true - 1| [%] over the unseen board's true modes below 1 kHz, paired by MAC at
    the test grid, with the library ``lib`` (None: the shipped one) searched first. Printed beside: the
    standard deviation the library's values give each frequency (build --uncertainty); it covers the
    family means only, not this board's own part scatter nor its mesh."""
    truth = load_board(d / "b4_truth.toml").build().model
    with chosen([] if lib is None else [lib]):
        structure, stds = library_uncertainty(load_board(board))
    pm = structure.build()
    model = pm.model
    pts, dofs = grid("b4")
    mt, mm = solve_modes(truth, n_modes=10), solve_modes(model, n_modes=12)

    def read(m, modes):
        return np.asarray(model_probe(m, pts.xyz, dofs.directions).P @ modes.shapes)

    below = mt.frequencies < 1000.0
    pairs = mac(read(truth, mt)[:, below], read(model, mm)).argmax(axis=1)
    err = 100 * (mm.frequencies[pairs] / mt.frequencies[below] - 1)
    sd = frequency_std(pm, mm, stds)[pairs]
    print(f"  {label:>24}: " + "  ".join(f"{f:6.1f} Hz {e:+5.2f} % (sd {100 * s / f:.2f} %)"
                                         for f, e, s in zip(mt.frequencies[below], err, sd)))
    assert np.all(sd > 0) == bool(stds)
    return np.max(np.abs(err))


def test_calibrate_three_boards_and_predict_a_fourth(cases):
    d, case = cases
    # one run per board into one library: the library pools them (stated test noise)
    runs = [calibrate([*case[n][:2], "--library", d / "lib_seq", "--noise", "f=0.2,shape=2"], d / f"{n}.json")[0]
            for n in BOARDS]
    seq = runs[-1]
    assert all(f["n_calibrations"] == 3 and not f["flagged"] for f in seq["families"].values()), seq["families"]
    assert runs[0]["before"]["max_freq_error_pct"] > 5.0  # the shipped 3.5 mm
    assert all(r["after"]["max_freq_error_pct"] < 1.0 for r in runs)
    assert runs[1]["families"]["PGA"]["before_m"] == pytest.approx(runs[0]["families"]["PGA"]["equivalent_thickness_m"],
                                                                   rel=1e-5)  # the library value, 6 digits
    check_families(seq["families"], "three runs pooled by the library")
    # all three boards in one stacked problem (noise estimated from the residual)
    (d / "calibration.toml").write_text("".join(f'[[boards]]\nboard = "{n}.toml"\ntest = "{n}_test.uff"\n\n'
                                                for n in BOARDS))
    joint, _ = calibrate(["--joint", d / "calibration.toml", "--library", d / "lib_joint"], d / "joint.json")
    assert joint["library"] == str(d / "lib_joint") and len(joint["before"]["configurations"]) == 3
    assert joint["after"]["max_freq_error_pct"] < joint["before"]["max_freq_error_pct"]
    check_families(joint["families"], "one joint run over the three boards")
    # the unseen fourth board
    b4, _, _ = case["b4"]
    print("\nunseen board b4, model vs truth (modes below 1 kHz):")
    uncal = predict_unseen(d, b4, None, "uncalibrated (3.5 mm)")
    seq_err = predict_unseen(d, b4, d / "lib_seq", "library of three runs")
    joint_err = predict_unseen(d, b4, d / "lib_joint", "library of the joint run")
    assert uncal > 3.0
    assert seq_err < 1.5 and joint_err < 1.5
