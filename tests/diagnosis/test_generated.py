"""A handful of the discovery benchmark's generated cases (issue 37, benchmarks/discovery): boards pcbdyn
never modelled (random outline, laminate, parts and fixtures, declared values off), their truth solved in
OpenSees on a mesh twice as fine as the model's, kept in ``generated/`` with their truth
(:mod:`fixtures`). Each is judged as the benchmark judges (:mod:`score`): every hidden effect of
detectable size found (kind, place, magnitude), none invented, and where effects were found the error
after at most 0.5 %; a case without effects reports none."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks" / "discovery"))
from cases import Case  # noqa: E402
from detectability import DETECTABLE_CHI2  # noqa: E402
from make import noisy_test  # noqa: E402
from score import judge  # noqa: E402

from pcbdyn.cli import main  # noqa: E402
from pcbdyn.testdata.uff import write_uff  # noqa: E402

HERE = Path(__file__).resolve().parent / "generated"
AFTER_MAX_PCT = 0.5
#: generated cases the diagnosis does not yet pass, and what it does instead (strict: a pass is news)
MISSED = {"s0012": "a 19 x 28 mm region 2.3 x stiffer near the free end of a narrow board clamped on one edge "
                   "(chi^2 12600 beyond the parameters) is not reported: 2.0 % is left after",
          "s0033": "the bracket (a 12 g mass on a 16 N/mm spring near the edge x = 0) is found, 0.32 % after, but a "
                   "0.14 +- 0.04 g line mass along that edge is reported beside it (the removal check keeps it); "
                   "the same case run by the benchmark (its cached test file, --workers 1) reports the bracket "
                   "alone: the two runs differ in the test file's digits or the workers (not traced)"}


def _cases():
    return [pytest.param(p, id=p.stem, marks=[pytest.mark.xdist_group(p.stem)] + (
        [pytest.mark.xfail(reason=MISSED[p.stem], strict=True)] if p.stem in MISSED else []))
            for p in sorted(HERE.glob("s*.json"))]


@pytest.mark.slow
@pytest.mark.parametrize("fixture", _cases())
def test_generated_case(fixture, tmp_path):
    data = json.loads(fixture.read_text())
    case = Case.from_json(data["case"])
    board = tmp_path / "board.toml"
    board.write_text(data["board_toml"])
    write_uff(tmp_path / "test.uff", noisy_test(case, data["frequencies_hz"], data["shapes_z"]))
    js = tmp_path / "d.json"
    r = CliRunner().invoke(main, ["diagnose", str(board), str(tmp_path / "test.uff"), "--noise",
                                  "f={:g},shape={:g}".format(*case.noise), "--json", str(js)])
    assert r.exit_code == 0, r.output
    result = json.loads(js.read_text())
    v = judge({"case": data["case"], "signal_chi2": data["signal_chi2"]}, result, DETECTABLE_CHI2)
    missed = [a for a in v["atoms"] if a["detectable"] and not a["found"]]
    assert not missed, f"{fixture.stem}: not found {missed}; reported {result['effects']}"
    assert not v["invented"], f"{fixture.stem}: invented {v['invented']}"
    if case.effects:
        assert result["after"]["max_freq_error_pct"] <= AFTER_MAX_PCT
    else:
        assert result["effects"] == []
