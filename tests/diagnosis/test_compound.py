"""Additions that bring stiffness and mass together (issue 26): ``pcbdyn diagnose`` on simulated tests
(:mod:`bench_cases`: the truth meshed four times finer than the model, 0.2 % / 2 % noise) of the
free six-part card carrying

- an aluminium flat bar 10 x 4 mm glued across the card: a beam with its own mass (17.5 g over the
  162 mm), found as a ``stiffener`` whose section (aluminium, 4 mm high, :class:`RibSection`) makes
  its mass follow from its bending stiffness;
- a bracket: a 15 g mass on a 1e5 N/m spring to the frame at one point, found as a mass and the
  spring under it: the card's bounce on the spring (test mode 1, 95 Hz) has no partner among the free
  model's elastic modes, and its rigid-body shape places and sizes the spring (:mod:`pcbdyn.diagnosis.support`).

Each: every part of the addition within 30 % and the max frequency error after <= 0.5 %.

The bar is found since the held-out check may also follow the secant of a large addition
(:func:`pcbdyn.diagnosis.select._kept`), and placed on its line and sized there once the card is meshed
along it (:mod:`pcbdyn.diagnosis.conforming`: embedded in the model's cells it stayed 0.7 mm off and left
0.61 % after). The same two additions on data from another FE code are the hold-out cases ``ho_al_bar`` and
``ho_bracket`` (:mod:`holdout_cases`, :mod:`test_holdout`).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_cases as bc  # noqa: E402
from test_diagnose_bench import match  # noqa: E402

from pcbdyn.board.entries import RibSection  # noqa: E402
from pcbdyn.cli import main  # noqa: E402
from pcbdyn.diagnosis import geometry_fit  # noqa: E402

BAR_B, SECTION = 10e-3, RibSection()
BAR_EI = SECTION.E * BAR_B * SECTION.h**3 / 12.0  # 3.73 N m^2
BAR_Y = 0.112
BRACKET_AT = (0.081, 0.113)
BAR = bc.Case("compound_al_bar", "card", (bc.Effect("stiffener", BAR_EI, path=((0.0, BAR_Y), (0.162, BAR_Y))),),
              true_values=bc.CARD_TRUE, seed=21, note="an aluminium flat bar 10 x 4 mm glued across the card")
BRACKET = bc.Case("compound_bracket", "card", (bc.Effect("point_mass", 15e-3, at=BRACKET_AT),
                                               bc.Effect("ground_spring", 1e5, at=BRACKET_AT)),
                  true_values=bc.CARD_TRUE, seed=22, note="a 15 g bracket on a 1e5 N/m spring to the frame")


def _diagnose(case, folder: Path, kinds: str) -> tuple:
    board, uffs, truth = bc.make_case(case, folder)
    js = folder / "d.json"
    args = ["diagnose", str(board), *bc.cli_tests(case, uffs), "--noise", f"f={case.noise[0]:g},shape={case.noise[1]:g}",
            "--kinds", kinds, "--json", str(js)]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    return json.loads(js.read_text()), truth


def _bar_mass(EI: float, length: float) -> float:
    """Mass [kg] of a rib of the section's material and height with bending stiffness ``EI``."""
    return SECTION.rho * (12.0 * EI / (SECTION.E * SECTION.h**3)) * SECTION.h * length


@pytest.fixture(scope="module")
def bar(tmp_path_factory):
    """The diagnosis of the card with the bar, and the bar's truth entry."""
    data, truth = _diagnose(BAR, tmp_path_factory.mktemp("bar"), "stiffener,point_mass,line_mass")
    (t,) = truth["effects"]
    return data, t


@pytest.mark.slow
@pytest.mark.xdist_group("compound_bar")
def test_glued_aluminium_bar_found_with_its_stiffness_and_mass(bar):
    """Found since the held-out check follows the secant of the addition (nothing was reported while it
    was linearised at the state without the bar: 5 of 7 modes predicted better, 0.71 < 0.75)."""
    data, t = bar
    e, d = match(data["effects"], t)
    assert e is not None and d <= max(15.0, 1e3 * bc.MODEL_MESH), data["effects"]
    assert e["magnitude"] == pytest.approx(BAR_EI, rel=0.30)
    true_mass = _bar_mass(BAR_EI, 0.162)
    found_mass = _bar_mass(e["magnitude"], 1e-3 * abs(e["path_mm"][1][0] - e["path_mm"][0][0]))
    found_mass += sum(x["magnitude"] for x in data["effects"] if x["type"] in ("point_mass", "line_mass"))
    assert true_mass == pytest.approx(17.5e-3, rel=0.01) and found_mass == pytest.approx(true_mass, rel=0.30)
    assert data["parameters_only"]["max_freq_error_pct"] > 2.0


@pytest.mark.slow
@pytest.mark.xdist_group("compound_bar")
def test_glued_bar_placed_on_its_line(bar):
    """On the card meshed along it, the bar is walked to its line: both ends within the shortest step
    of the move across it (0.42 mm on the model's 6.75 mm elements; embedded in them it stayed 0.7 mm
    off). A tighter bound reads the re-meshing's noise in chi^2: one commit put the first end 0.31 mm
    off alone and within 0.25 mm in the suite's process."""
    data, t = bar
    e, _ = match(data["effects"], t)
    resolution = 1e3 * bc.MODEL_MESH * geometry_fit.MOVES["across"] * geometry_fit.STEP_RANGE[0]
    assert e is not None and resolution < 0.7
    assert all(abs(end[1] - 1e3 * BAR_Y) <= resolution for end in e["path_mm"]), e


@pytest.fixture(scope="module")
def bracket(tmp_path_factory):
    """The diagnosis of the card with the bracket, and the truth's entries."""
    data, truth = _diagnose(BRACKET, tmp_path_factory.mktemp("bracket"), "point_mass,ground_spring")
    return data, truth["effects"]


@pytest.mark.slow
@pytest.mark.xdist_group("compound_bracket")
def test_bracket_found_as_a_mass_on_a_spring(bracket):
    """Both parts within 30 %; the spring placed between nodes from the bounce's rigid-body part to
    within a millimetre of the truth's (the model's nodes are 6.75 mm apart); the bounce is reported
    as the support's evidence and paired after, not before."""
    data, truth = bracket
    for t in truth:
        e, d = match(data["effects"], t)
        assert e is not None and d <= 15.0, (t["type"], data["effects"])
        assert e["magnitude"] == pytest.approx(t["magnitude"], rel=0.30), (t["type"], e)
        if t["type"] == "ground_spring":
            assert d <= 1.0
    # the parameters alone leave what the noise cannot give (their frequencies within 1.5 % since the fit
    # reported is update's where it pairs them better), and the bracket takes the error below that
    assert data["statistics"]["p_value_noise"] < data["statistics"]["alpha"]
    assert data["after"]["max_freq_error_pct"] < data["parameters_only"]["max_freq_error_pct"]
    assert data["statistics"]["support_test_modes"] == {"base": [1]}
    before, after = (data[k]["configurations"][0] for k in ("before", "after"))
    assert before["unpaired_test_modes"] == [1] and "unpaired_test_modes" not in after


@pytest.mark.slow
@pytest.mark.parametrize("addition", [
    pytest.param("bar", marks=pytest.mark.xdist_group("compound_bar")),
    pytest.param("bracket", marks=pytest.mark.xdist_group("compound_bracket")),
])
def test_addition_leaves_at_most_half_a_percent(addition, request):
    data, _ = request.getfixturevalue(addition)
    assert data["after"]["max_freq_error_pct"] <= 0.5
