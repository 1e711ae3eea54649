"""The thesis' six-part card calibrated from its measured frequencies (Table 7.2): configuration 1,
then configurations 1+2+3 (PBC), one equivalent thickness per family, printed beside the thesis'
per-part values of Table 7.6 (resonance-frequency based updating with six thicknesses).

The card's layout is a reconstruction (reference README) and the thesis' own model differs from ours
by up to 2.8 % before updating, so Table 7.6 is a comparison, not a target: what must hold is the
thesis' own criterion (max frequency error below 5 % after updating, section 7.3.1), a drop of the
error, finite standard deviations, the two calibrations agreeing within their standard deviations,
and each run recorded in the library with the hashes of the board and the data it came from."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pandas as pd
import pytest
from click.testing import CliRunner

from pcbdyn.cli import main
from pcbdyn.components.writer import read_entry

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"
#: thesis Table 7.6, RF-based updating, T [mm] of groups 1-6 (parts U1-U6: PGA, JLCC, CQFP, JLCC, CQFP, PGA)
TABLE_7_6_RF = {"PGA": (3.19, 3.79), "JLCC": (4.95, 3.61), "CQFP": (4.89, 4.1)}
#: the measured modes used: configuration 1 modes 1-6 (as Table 7.5; mode 7 is badly identified, section
#: 7.3.6); configurations 2 and 3 as far as their modes pair with ours by order (frequencies carry no shapes)
SELECT = {"c1": {"c1": range(1, 7)}, "c123": {"c1": range(1, 7), "c2": range(1, 4), "c3": range(1, 7)}}
#: the thesis' element size along x (its 112 SHELL63 elements, section 7.3.5); the card's own 6.75 mm
#: gives the same values within a third of their standard deviations, four times slower
MESH = "13.5 mm"


def frequency_table(tmp_path, name) -> Path:
    df = pd.read_csv(CARD / "measured_frequencies_table_7_2.csv", comment="#")
    keep = pd.concat([df[(df.configuration == c) & df["mode"].isin(m)] for c, m in SELECT[name].items()])
    path = tmp_path / f"{name}.csv"
    keep[["configuration", "mode", "frequency_hz"]].to_csv(path, index=False)
    return path


def test_six_part_card_from_table_7_2(tmp_path):
    shutil.copy(CARD / "board.toml", tmp_path / "card.toml")
    results = {}
    for name in SELECT:
        csv = frequency_table(tmp_path, name)
        js = tmp_path / f"{name}.json"
        args = ["calibrate", tmp_path / "card.toml", "--frequencies", csv, "--library", tmp_path / f"lib_{name}",
                "--mesh-size", MESH, "--json", js]
        r = CliRunner().invoke(main, list(map(str, args)))
        assert r.exit_code == 0, r.output
        results[name] = json.loads(js.read_text())
    print(f"\n{'family':>6} {'Table 7.6 RF (per part) [mm]':>30} {'c1 [mm]':>16} {'c1+c2+c3 [mm]':>16}")
    for fam, parts in TABLE_7_6_RF.items():
        row = [f"{results[n]['families'][fam]['equivalent_thickness_m'] * 1e3:.2f} +- "
               f"{results[n]['families'][fam]['std_m'] * 1e3:.2f}" for n in SELECT]
        print(f"{fam:>6} {' / '.join(map(str, parts)):>22} (mean {sum(parts) / 2:.2f}) {row[0]:>16} {row[1]:>16}")
    for name, data in results.items():
        print(f"{name}: max |df| {data['before']['max_freq_error_pct']:.2f} % -> {data['after']['max_freq_error_pct']:.2f} %")
        assert data["before"]["max_freq_error_pct"] > 5.0 > data["after"]["max_freq_error_pct"]
        assert {"families", "before", "after", "library"} <= set(data) and data["library"].endswith(f"lib_{name}")
        for fam, d in data["families"].items():
            assert {"equivalent_thickness_m", "std_m", "before_m", "n_calibrations", "flagged"} <= set(d)
            assert 0 < d["std_m"] < d["equivalent_thickness_m"] and d["before_m"] == pytest.approx(3.5e-3)
            assert d["n_calibrations"] == 1 and not d["flagged"]
    for fam in TABLE_7_6_RF:  # configuration 1 alone and with the perturbed configurations agree
        a, b = (results[n]["families"][fam] for n in SELECT)
        assert abs(a["equivalent_thickness_m"] - b["equivalent_thickness_m"]) < 3 * max(a["std_m"], b["std_m"])
    _, pkg, records = read_entry(tmp_path / "lib_c123" / "JLCC.toml")
    rec = records[0]
    assert pkg.equivalent_thickness == pytest.approx(results["c123"]["families"]["JLCC"]["equivalent_thickness_m"], rel=1e-5)
    assert rec.boards[0]["sha256"] == hashlib.sha256((tmp_path / "card.toml").read_bytes()).hexdigest()
    assert {t["configuration"] for t in rec.tests} == {"base", "c2", "c3"}
    assert rec.tests[0]["sha256"] == hashlib.sha256((tmp_path / "c123.csv").read_bytes()).hexdigest()
    assert rec.extra["parts"] == ["card.toml:U2", "card.toml:U4"] and rec.method == "freq"
