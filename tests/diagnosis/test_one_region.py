"""A region found as two overlapping or side-by-side rectangles refitted as one
(:mod:`pcbdyn.diagnosis.one_region`), two regions that are two left as they are, and a region walked to
its extent by the local search (:func:`pcbdyn.diagnosis.select.refine`). The card of
:func:`diagnosis_plates.guided_card` (13.3 x 12.9 mm elements), frequencies with 0.2 % noise."""

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.merge import linked
from pcbdyn.diagnosis.moves import LocalMoves, rectangle
from pcbdyn.diagnosis.one_region import as_one_region, side_by_side, starts
from pcbdyn.diagnosis.region_stiffness import KIND
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.select import estimate, refine
from pcbdyn.diagnosis.selection import Selection, penalty
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import MeasuredModes

from diagnosis_plates import guided_card

N_MODES, SIGMA = 8, 0.002
DX, DY = 0.16 / 12, 0.18 / 14  # the card's element sizes


@pytest.fixture(scope="module")
def card():
    m = guided_card()
    return m, dg.from_model(m)


def _pair_fitted(m, layout, truth, boxes, v0):
    """The card's frequencies with the regions ``truth`` [(rectangle, change)], noise added, and the
    selection of the regions ``boxes`` fitted to them: (residual, candidates, moves, selection)."""
    model = m
    for box, s in truth:
        model = dg.add_effect(model, KIND.rectangle(layout, *box), s)
    f = solve_modes(model, n_modes=N_MODES).frequencies
    f = f * (1.0 + SIGMA * np.random.default_rng(1).standard_normal(N_MODES))
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(N_MODES, SIGMA))], lambda p: [m])
    cands: list = []
    moves = LocalMoves(layout, cands, DX)
    idx = [moves.region("region_stiffness", b) for b in boxes]
    fit = estimate(res, np.zeros(0), [cands[i] for i in idx], v0, 8)
    pen = penalty(res.n_rows, len(cands))
    sel = Selection(chosen=idx, values=fit.values, p=fit.p, chi2=[fit.chi2], criterion=[fit.chi2 + len(idx) * pen],
                    state=fit.state)
    return res, cands, moves, sel


def test_a_region_between_two_grid_rectangles_becomes_one(card):
    """A 53 x 51 mm region 50 % softer, fitted first as two rectangles offset from it by two elements
    (one left, one down, as a grid of patches meets it; their union is twice its area and the
    area-weighted change over it -0.29): refitted as one rectangle on the truth's cells and the change
    within 5 %, at the noise's chi^2."""
    m, layout = card
    truth = (3 * DX, 4 * DY, 7 * DX, 8 * DY)
    res, cands, moves, sel = _pair_fitted(m, layout, [(truth, -0.5)],
                                          [(1 * DX, 4 * DY, 5 * DX, 8 * DY), (3 * DX, 2 * DY, 7 * DX, 6 * DY)],
                                          [-0.3, -0.3])
    pair = sel.chi2[-1]
    as_one_region(res, cands, sel, moves, 0.03)
    assert [cands[i].kind for i in sel.chosen] == ["region_stiffness"]
    assert np.abs(np.subtract(rectangle(cands[sel.chosen[0]]), truth)).max() < 0.5 * DX
    assert sel.values[0] == pytest.approx(-0.5, rel=0.05)
    assert sel.chi2[-1] < min(pair, 4 * N_MODES)


def test_a_region_found_as_two_rectangles_side_by_side_becomes_one(card):
    """The same region fitted first as two rectangles that meet along a side (each one element longer
    than its half of the truth, outward; as the search's grid meets a region across two of its cells):
    they do not overlap, yet they are one region, refitted as one rectangle on the truth's cells, the
    change within 5 %, at the noise's chi^2 (as dev seed 2 reports a softening of -0.68: two such
    rectangles, -0.66 and -0.68)."""
    m, layout = card
    truth = (3 * DX, 4 * DY, 7 * DX, 8 * DY)
    res, cands, moves, sel = _pair_fitted(m, layout, [(truth, -0.5)],
                                          [(3 * DX, 3 * DY, 7 * DX, 6 * DY), (3 * DX, 6 * DY, 7 * DX, 9 * DY)],
                                          [-0.3, -0.3])
    as_one_region(res, cands, sel, moves, 0.03)
    assert [cands[i].kind for i in sel.chosen] == ["region_stiffness"]
    assert np.abs(np.subtract(rectangle(cands[sel.chosen[0]]), truth)).max() < 0.5 * DX
    assert sel.values[0] == pytest.approx(-0.5, rel=0.05)
    assert sel.chi2[-1] < 4 * N_MODES


def test_regions_side_by_side_are_tried_as_one_not_reported_as_one(card):
    """Rectangles of one kind that share part of a side are tried as one region; not where they meet
    at a corner only. Unlike overlapping ones, they are not reported as one (:func:`.merge.linked`)
    where the refit as one is refused."""
    _, layout = card
    a = KIND.rectangle(layout, 1 * DX, 2 * DY, 5 * DX, 6 * DY)
    side = KIND.rectangle(layout, 5 * DX, 4 * DY, 8 * DX, 9 * DY)
    corner = KIND.rectangle(layout, 5 * DX, 6 * DY, 8 * DX, 9 * DY)
    assert side_by_side(a, side) and not side_by_side(a, corner)
    assert not linked(a, side, 0.03)


def test_refine_narrows_a_region_from_both_sides_to_the_truth(card):
    """A 4 x 4 element region 50 % softer, found over a rectangle twice as wide (one element more on each
    side in x): the rectangle one element wider than the truth on both sides is a local minimum for
    moves of one side (each raises chi^2), and the local search reaches the truth only by moving both
    sides of an axis at once (:func:`pcbdyn.diagnosis.moves._rect_moves`): the truth's cells, the change
    within 2 %, at the noise's chi^2."""
    m, layout = card
    truth = (3 * DX, 4 * DY, 7 * DX, 8 * DY)
    res, cands, moves, sel = _pair_fitted(m, layout, [(truth, -0.5)], [(2 * DX, 4 * DY, 8 * DX, 8 * DY)], [-0.3])
    one_side = [j for j in moves(sel.chosen[0])
                if np.count_nonzero(np.abs(np.subtract(rectangle(cands[j]), rectangle(cands[sel.chosen[0]]))) > 1e-9) == 1]
    assert len(one_side) == 8
    assert min(estimate(res, sel.p, [cands[j]], sel.values, 8).chi2 for j in one_side) > sel.chi2[-1]
    out = refine(res, cands, sel, moves, None)
    assert np.abs(np.subtract(rectangle(cands[out.chosen[0]]), truth)).max() < 0.5 * DX
    assert out.values[0] == pytest.approx(-0.5, rel=0.02)
    assert out.chi2[-1] < 2 * N_MODES


def test_a_stiffening_found_too_small_grows_to_the_truth(card):
    """A 4 x 4 element region 1.3 stiffer, found first over its middle 2 x 2 elements (where it fits at a
    change of about 4): each step of the local search starts the change at the one that keeps its
    integral over the board (``moved_value``), so that the growing region is not left far too stiff,
    and the search reaches the truth's cells, the change within 2 %, at the noise's chi^2. Started at
    the change held, the search had stopped over 2 x 4 elements at 4.3, chi^2 66."""
    m, layout = card
    truth = (3 * DX, 4 * DY, 7 * DX, 8 * DY)
    res, cands, moves, sel = _pair_fitted(m, layout, [(truth, 1.3)], [(4 * DX, 5 * DY, 6 * DX, 7 * DY)], [0.5])
    out = refine(res, cands, sel, moves, None)
    assert np.abs(np.subtract(rectangle(cands[out.chosen[0]]), truth)).max() < 0.5 * DX
    assert out.values[0] == pytest.approx(1.3, rel=0.02)
    assert out.chi2[-1] < 2 * N_MODES


def test_a_moved_region_starts_at_the_same_integral(card):
    """A stiffness change moved to a region of twice the cells' area starts at half the change; a mass
    moved keeps its mass."""
    _, layout = card
    a = KIND.rectangle(layout, 2 * DX, 2 * DY, 4 * DX, 4 * DY)
    b = KIND.rectangle(layout, 2 * DX, 2 * DY, 6 * DX, 4 * DY)
    assert b.data["area"] == pytest.approx(2 * a.data["area"], rel=1e-9)
    assert a.data["area"] == pytest.approx(4 * DX * DY, rel=1e-9)
    assert KIND.moved_value(a, b, 0.8) == pytest.approx(0.4)
    assert dg.KINDS["region_mass"].moved_value(a, b, 0.01) == 0.01


def test_two_overlapping_regions_stay_two(card):
    """A softer and a stiffer region that overlap: one rectangle cannot stand for them, and the
    criterion keeps both, unchanged."""
    m, layout = card
    a, b = (1 * DX, 2 * DY, 5 * DX, 8 * DY), (3 * DX, 6 * DY, 10 * DX, 11 * DY)
    res, cands, moves, sel = _pair_fitted(m, layout, [(a, -0.4), (b, 0.8)], [a, b], [-0.3, 0.3])
    before = (list(sel.chosen), sel.values.copy())
    as_one_region(res, cands, sel, moves, 0.03)
    assert sel.chosen == before[0] and np.array_equal(sel.values, before[1])


def test_the_starts_keep_the_change_where_regions_overlap():
    """Changes add where regions overlap: two rectangles of -0.2 and -0.3 give their intersection -0.5,
    and a rectangle twice the size of one of them half its change; masses are shared by area."""
    a, b = (0.0, 0.0, 0.02, 0.02), (0.01, 0.0, 0.03, 0.02)
    got = dict(starts([a, b], [-0.2, -0.3], "region_stiffness"))
    assert got[(0.01, 0.0, 0.02, 0.02)] == pytest.approx(-0.5)
    assert got[(0.0, 0.0, 0.03, 0.02)] == pytest.approx((-0.2 * 2 - 0.3 * 2) / 3)
    masses = dict(starts([a, b], [0.002, 0.004], "region_mass"))
    assert masses[(0.0, 0.0, 0.03, 0.02)] == pytest.approx(0.006)
    assert masses[(0.01, 0.0, 0.02, 0.02)] == pytest.approx(0.003)


def test_the_places_the_data_do_not_tell_apart_widen_a_region_s_magnitude(card):
    """A 4 x 4 element region 1.3 stiffer, fitted over 3 x 3 of its elements (one in from two sides), where
    it fits at a change of about 2.8: the data fix the change times the area, so the profile over places
    (:func:`pcbdyn.diagnosis.uncertainty.place_range`) walks to larger regions at smaller changes and to
    smaller ones at larger changes within the 2-sigma rise, and its range holds the truth's 1.3, which the
    fit at its place excludes by its own profile."""
    from pcbdyn.diagnosis.uncertainty import place_range, profile_interval

    m, layout = card
    truth = (3 * DX, 4 * DY, 7 * DX, 8 * DY)
    res, cands, moves, sel = _pair_fitted(m, layout, [(truth, 1.3)], [(4 * DX, 4 * DY, 7 * DX, 7 * DY)], [0.5])
    chosen = [cands[i] for i in sel.chosen]
    assert sel.values[0] > 2.0
    lo, hi = profile_interval(res, sel.state, chosen, 0)
    assert lo > 1.3  # at its place, the change is known to exclude the truth's
    lo, hi = place_range(res, sel.state, chosen, 0, moves.around)
    assert lo < 1.3 < hi and hi > sel.values[0]
