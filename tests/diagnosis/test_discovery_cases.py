"""The discovery benchmark's generator (benchmarks/discovery/cases.py): cases drawn from seeds as issue
37 asks (sizes, thicknesses, 0-15 parts, 0-2 effects, 20-120 points, declared values a few % to 40 %
off), the same case for the same seed, and boards that pcbdyn reads both as handed and as true."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import shapely
from scipy.stats import kstest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks" / "discovery"))
from cases import DEV, REPORT, draw  # noqa: E402
from toml_text import board_text  # noqa: E402

from pcbdyn.board import load_board  # noqa: E402


def test_cases_are_drawn_as_the_issue_asks():
    cases = [draw(s) for s in range(40)]
    assert set(DEV).isdisjoint(REPORT) and len(DEV) == len(REPORT) == 200
    for c in cases:
        outline = shapely.Polygon(c.outline)
        W, H = outline.bounds[2], outline.bounds[3]
        assert 60 <= W <= 250 and 60 <= H <= 250 and 0.8 <= c.thickness_mm <= 3.2
        assert 0 <= len(c.parts) <= 15 and len(c.effects) <= 2
        assert 20 <= len(c.points) * 1.25 and len(c.points) <= 130
        assert all(outline.contains(shapely.Point(p)) for p in c.points)
        for p in c.parameters:
            off = abs(np.log(p["true"] / p["nominal"]))
            assert np.log(1.03) * 0.99 <= off <= np.log(1 / 0.6) * 1.01
    kinds = {e["kind"] for c in cases for e in c.effects}
    holds = {c.hold for c in cases}
    assert len(kinds) >= 7 and holds == {"free", "standoffs", "guides", "edges", "mixed"}
    # places are not on a grid: the effects' coordinates' fractions of a millimetre are uniform
    at = np.array([e["at"] for c in cases for e in c.effects if "at" in e]).ravel()
    assert kstest(at % 1.0, "uniform").pvalue > 0.01
    assert draw(7).to_json() == draw(7).to_json()


def test_handed_and_true_boards_load(tmp_path):
    for seed in (0, 5, 13, 22):
        c = draw(seed)
        for truth in (False, True):
            path = tmp_path / f"{seed}_{truth}.toml"
            path.write_text(board_text(c, truth, c.mesh_mm / 2 if truth else None))
            board = load_board(path)
            assert len(board.components) == len(c.parts) + sum(e["kind"] == "heat_sink" for e in c.effects) * truth
            if not truth:
                assert [p.name for p in board.parameters] == [p["name"] for p in c.parameters]


def test_coverage_is_judged_on_the_reported_intervals():
    """A magnitude reported as 10 with the 2-sigma interval [6, 12] (its profile wider below): the
    1-sigma interval is [8, 11], and an open upper end covers every larger truth."""
    from score import _covered

    r = {"magnitude": 10.0, "interval_2sigma": [6.0, 12.0]}
    assert [_covered(r, t) for t in (5.9, 6.1, 11.9, 12.1)] == [False, True, True, False]
    assert [_covered(r, t, 1.0) for t in (7.9, 8.1, 10.9, 11.1)] == [False, True, True, False]
    assert _covered({"magnitude": 10.0, "interval_2sigma": [6.0, None]}, 1e9, 1.0)
    assert [_covered({"magnitude": 10.0, "uncertainty": 1.0}, t, 1.0) for t in (8.9, 10.9)] == [False, True]


def test_a_rotary_inertia_is_not_judged_as_a_mass():
    """A point mass's rotary inertia reported at a drawn point mass's place (kg m^2, not kg) neither
    finds that mass nor stands in for it: the mass reported beside it does, and the inertia is invented
    only where no atom of its type exists."""
    from score import judge

    case = {"effects": [{"kind": "point_mass", "at": [50.0, 40.0], "mass": 0.01}], "parameters": [], "E": 2e10}
    truth = {"case": case, "signal_chi2": [1e4]}
    inertia = {"type": "point_mass", "parameter": "inertia", "at_mm": [50.0, 40.0], "magnitude": 2e-7}
    mass = {"type": "point_mass", "parameter": "mass", "at_mm": [51.0, 40.0], "magnitude": 0.0105}
    both = judge(truth, {"effects": [inertia, mass]}, 100.0)
    assert both["atoms"][0]["found"] and both["atoms"][0]["reported"] == 0.0105
    assert both["invented"] == [("point_mass", [50.0, 40.0])]
    alone = judge(truth, {"effects": [inertia]}, 100.0)
    assert not alone["atoms"][0]["placed"]


def test_housings_are_drawn_as_the_issue_asks(tmp_path):
    """Ribbed housings (benchmarks/discovery/housings.py): 3-5 plates, 0-6 ribs, walls held on the base, 0-2
    hidden effects on the plates (masses, ribs that may stop short), 20-120 points on the plates, declared
    values a few % to 40 % off; the handed and the true box.toml load, the truth with its effects as a box
    entry each, and the same housing comes from the same seed."""
    from housings import box_text
    from housings import draw as draw_housing

    from pcbdyn.box import load_box

    housings = [draw_housing(s) for s in range(30)]
    for h in housings:
        assert 3 <= len(h.plates) <= 5 and len(h.ribs) <= 6 and len(h.effects) <= 2
        assert 20 * 0.8 <= len(h.points) <= 120 * 1.3
        for p in h.parameters:
            assert np.log(1.03) * 0.99 <= abs(np.log(p["true"] / p["nominal"])) <= np.log(1 / 0.6) * 1.01
    assert {len(h.plates) for h in housings} == {3, 4, 5} and {e["kind"] for h in housings for e in h.effects} == {
        "point_mass", "stiffener"}
    for h in housings[:6]:
        handed, true = (tmp_path / f"{h.name}_{t}.toml" for t in ("handed", "true"))
        handed.write_text(box_text(h))
        true.write_text(box_text(h, truth=True))
        box, truth = load_box(handed), load_box(true)
        assert [p.name for p in box.parameters] == [p["name"] for p in h.parameters]
        assert len(truth.masses) == sum(e["kind"] == "point_mass" for e in h.effects)
        assert len(truth.ribs) - len(box.ribs) == sum(e["kind"] == "stiffener" for e in h.effects)
        held = {s.plate for s in box.supports}
        assert held == {p["name"] for p in h.plates} - {"upper"}
        for xyz in np.asarray(h.points, float):  # on a plate: on one of the box's faces, within its sides
            assert np.any(np.isclose(xyz, 0.0) | np.isclose(xyz, h.size_mm))
            assert np.all((xyz >= -1e-9) & (xyz <= np.asarray(h.size_mm) + 1e-9))
    assert draw_housing(3).to_json() == draw_housing(3).to_json()


def test_a_housing_effect_is_judged_in_three_dimensions():
    """A rib found along a 3-D path on a housing's plate: judged by the farther end's distance to the reported
    line, in the box's frame."""
    from score import judge

    path = [[0.0, 50.0, 20.0], [0.0, 150.0, 20.0]]
    case = {"effects": [{"kind": "stiffener", "path": path, "EI": 1.0}], "parameters": []}
    truth = {"case": case, "signal_chi2": [1e4]}
    near = {"type": "stiffener", "path_mm": [[0.0, 55.0, 24.0], [0.0, 145.0, 24.0]], "magnitude": 1.1}
    far = {"type": "stiffener", "path_mm": [[0.0, 50.0, 60.0], [0.0, 150.0, 60.0]], "magnitude": 1.0}
    assert judge(truth, {"effects": [near]}, 100.0)["atoms"][0]["found"]
    assert not judge(truth, {"effects": [far]}, 100.0)["atoms"][0]["placed"]


def test_splits_are_named_by_seed_ranges_with_or_without_the_kind_repeated():
    from make import case_names

    assert case_names("3-4,h5") == ["s0003", "s0004", "h0005"]
    assert case_names("h1000-h1002,s7-s8") == case_names("h1000-1002,7-8") == ["h1000", "h1001", "h1002", "s0007",
                                                                            "s0008"]
