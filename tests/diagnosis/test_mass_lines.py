"""A mass spread along a line across the plate (:mod:`pcbdyn.diagnosis.line_mass`'s lines across the
plate) and two point masses found in its place refitted as that line (:mod:`pcbdyn.diagnosis.mass_lines`)."""

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.line_mass import KIND
from pcbdyn.diagnosis.mass_lines import as_lines
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.select import estimate
from pcbdyn.diagnosis.selection import Selection, penalty
from pcbdyn.fe import MassProperty, Model, ShellProperty
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import MeasuredModes

from diagnosis_plates import guided_card

N_MODES, SIGMA = 8, 0.002
ENDS = np.array([[0.031, 0.047], [0.118, 0.139]])  # a 127 mm line at 47 degrees, ends between nodes


@pytest.fixture(scope="module")
def card():
    """The guided card of :func:`diagnosis_plates.guided_card` (13 mm elements) and its layout."""
    m = guided_card()
    return m, dg.from_model(m)


def test_a_line_across_the_plate_keeps_its_mass_and_centre(card):
    """Spread to the nodes of the cells it crosses, a 12 g line adds 12 g in each direction and its
    centre of mass lies at the segment's midpoint (the shape functions reproduce linear fields), and
    it is rebuilt along the same segment on another mesh."""
    m, layout = card
    line = KIND.across(layout, *ENDS)
    assert line.data["length"] == pytest.approx(np.linalg.norm(ENDS[1] - ENDS[0]), rel=1e-9)
    _, M0 = assemble(m)
    _, M1 = assemble(dg.add_effect(m, line, 0.012))
    dM = (M1 - M0).diagonal()
    for d in (0, 1, 2):
        assert dM[d::6].sum() == pytest.approx(0.012, rel=1e-9)
    centre = dM[2::6] @ m.nodes[:, :2] / dM[2::6].sum()
    assert centre == pytest.approx(ENDS.mean(axis=0), abs=1e-9)
    nodes, conn = rectangle(0.16, 0.18, 20, 24)
    fine = Model(nodes)
    fine.add("plate", "quad4", conn, ShellProperty(26e9, 0.3, 2640.0, 2.8e-3))
    moved = dg.place(dg.from_model(fine), line)
    assert moved.name == line.name and np.allclose(moved.geometry["segment"], ENDS)


def _as_pair(m, layout, f_test, masses):
    """The selection of two point masses on the nodes nearest ``masses`` ((x, y) [m], kg) fitted to
    ``f_test``, then :func:`as_lines` on it: (candidates, selection, chi^2 of the pair)."""
    cands = [c for c in dg.generate(layout, kinds=["point_mass"])]
    by_node = {int(c.nodes[0]): i for i, c in enumerate(cands)}
    start = [by_node[int(np.linalg.norm(m.nodes[:, :2] - xy, axis=1).argmin())] for xy, _ in masses]
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[i] for i in start], [v for _, v in masses], 8)
    sel = Selection(chosen=start, values=fit.values, p=fit.p, chi2=[fit.chi2],
                    criterion=[fit.chi2 + 2 * penalty(res.n_rows, len(cands))], state=fit.state)
    return cands, as_lines(res, cands, sel, 0.02, layout, 0.0065), fit.chi2


def test_two_point_masses_standing_in_for_a_line_become_the_line(card):
    """A 12 g line across the card, first fitted as two point masses on the nodes nearest its
    two-point Gauss points: refitted as one line, its ends walked to within 3 mm of the truth's and its mass
    within 3 %, the frequencies fitted better than by the pair."""
    m, layout = card
    f_test = solve_modes(dg.add_effect(m, KIND.across(layout, *ENDS), 0.012), n_modes=N_MODES).frequencies
    mid, half = ENDS.mean(axis=0), 0.5 * (ENDS[1] - ENDS[0]) / np.sqrt(3.0)
    cands, sel, pair = _as_pair(m, layout, f_test, [(mid - half, 0.006), (mid + half, 0.006)])
    assert [cands[i].kind for i in sel.chosen] == ["line_mass"]
    seg = cands[sel.chosen[0]].geometry["segment"]
    assert np.linalg.norm(seg - ENDS, axis=1).max() < 0.003
    assert sel.values[0] == pytest.approx(0.012, rel=0.03)
    assert sel.chi2[-1] < pair


def test_two_unequal_masses_apart_stay_two(card):
    """A 20 g and a 5 g mass 95 mm apart are no line: the pair fits them, a line through them does
    not, and both stay point masses."""
    m, layout = card
    at = [np.array([0.04, 0.05]), np.array([0.11, 0.115])]
    truth = m.copy()
    for k, (xy, v) in enumerate(zip(at, (0.020, 0.005))):
        truth.add(f"hidden{k}", "mass", [[int(np.linalg.norm(m.nodes[:, :2] - xy, axis=1).argmin())]], MassProperty(v))
    cands, sel, _ = _as_pair(m, layout, solve_modes(truth, n_modes=N_MODES).frequencies, [(at[0], 0.02), (at[1], 0.005)])
    assert [cands[i].kind for i in sel.chosen] == ["point_mass", "point_mass"]
    assert sorted(sel.values) == pytest.approx([0.005, 0.020], rel=1e-3)


def test_a_body_standing_in_for_half_a_line_goes_with_its_inertia(card):
    """One of the two masses found as a body of :mod:`pcbdyn.diagnosis.bodies` (a mass and an inertia
    at one centre, as on dev seed 40): the line replaces the mass and the inertia with it."""
    from pcbdyn.diagnosis.bodies import _body

    m, layout = card
    f_test = solve_modes(dg.add_effect(m, KIND.across(layout, *ENDS), 0.012), n_modes=N_MODES).frequencies
    mid, half = ENDS.mean(axis=0), 0.5 * (ENDS[1] - ENDS[0]) / np.sqrt(3.0)
    cands = list(dg.generate(layout, kinds=["point_mass"]))
    near = min(range(len(cands)), key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], mid - half)))
    cands += list(_body(cands[near], np.r_[mid + half, 0.0], 0.004))
    start = [near, len(cands) - 2, len(cands) - 1]
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[i] for i in start], [0.006, 0.006, 1e-7], 8)
    sel = Selection(chosen=start, values=fit.values, p=fit.p, chi2=[fit.chi2],
                    criterion=[fit.chi2 + 3 * penalty(res.n_rows, len(cands))], state=fit.state)
    sel = as_lines(res, cands, sel, 0.02, layout, 0.0065)
    assert [cands[i].kind for i in sel.chosen] == ["line_mass"]
    assert sel.values[0] == pytest.approx(0.012, rel=0.03)


def test_one_point_mass_standing_in_for_a_line_becomes_the_line(card):
    """The 12 g line found as one point mass on the node nearest its centre (no pair to refit), the
    laminate's modulus declared 8 % low and fitted with it: tried as lines through that centre in
    four directions and seven lengths, the best walked, it becomes the line, its mass within 5 %, the
    modulus within 0.5 %, its frequencies fitted within the noise (chi^2 below the number of modes)
    and better than the point's by more than the penalty a line's direction and length pay; its ends
    within 15 mm of the truth's (eight frequencies at 0.2 % tell a line's ends no closer: the line
    12 mm off at one end fits them to chi^2 1.5)."""
    m, layout = card
    f_test = solve_modes(dg.add_effect(m, KIND.across(layout, *ENDS), 0.012), n_modes=N_MODES).frequencies
    cands = list(dg.generate(layout, kinds=["point_mass"]))
    near = min(range(len(cands)), key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], ENDS.mean(axis=0))))
    n = m.n_dof
    dK = assemble(guided_card(E=1.0), sets=["plate"])[0]
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [guided_card(E=p[0])], lambda p, models: [[(dK, sp.csr_matrix((n, n)))]], n_params=1)
    fit = estimate(res, np.array([24e9]), [cands[near]], [0.012], 8)
    pen = penalty(res.n_rows, len(cands))
    sel = Selection(chosen=[near], values=fit.values, p=fit.p, chi2=[fit.chi2], criterion=[fit.chi2 + pen],
                    state=fit.state)
    sel = as_lines(res, cands, sel, 0.02, layout, 0.0065)
    assert [cands[i].kind for i in sel.chosen] == ["line_mass"]
    assert np.linalg.norm(cands[sel.chosen[0]].geometry["segment"] - ENDS, axis=1).max() < 0.015
    assert sel.values[0] == pytest.approx(0.012, rel=0.05)
    assert sel.p[0] == pytest.approx(26e9, rel=0.005)
    assert sel.chi2[-1] < N_MODES and sel.chi2[-1] + pen < fit.chi2


@pytest.mark.parametrize("xy", [(0.0733, 0.0836), (0.06, 0.11), (0.10, 0.13)])
def test_a_point_mass_between_the_nodes_is_no_short_line(card, xy):
    """A 20 g point mass inside a cell (interpolated between its nodes), found as a point mass on the
    nearest node: a line of the same mass 17-25 mm long fits the frequencies better than the node
    does (it spreads the mass over the nodes around the point), but a line under two elements
    (26 mm) is none the mesh resolves, and the mass stays a point with the mass fitted on its node."""
    from dataclasses import replace

    from pcbdyn.diagnosis.point_mass import MASS

    m, layout = card
    cands = list(dg.generate(layout, kinds=["point_mass"]))
    near = min(range(len(cands)), key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], xy)))
    assert np.linalg.norm(np.subtract(cands[near].at[:2], xy)) > 0.004  # the point is not on a node
    truth = dg.add_effect(m, MASS.place(layout, replace(cands[near], at=xy)), 0.020)
    f_test = solve_modes(truth, n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[near]], [0.020], 8)
    sel = Selection(chosen=[near], values=fit.values, p=fit.p, chi2=[fit.chi2],
                    criterion=[fit.chi2 + penalty(res.n_rows, len(cands))], state=fit.state)
    sel = as_lines(res, cands, sel, 0.02, layout, 0.0065)
    assert [cands[i].kind for i in sel.chosen] == ["point_mass"]
    assert sel.values == pytest.approx(fit.values, rel=1e-12)



@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_a_mass_spread_over_one_element_is_no_line_two_elements_long(card, angle):
    """A 20 g mass spread along 13 mm (one element) inside a cell, found as one point mass at its
    centre: lines through it fit the frequencies better than the point does (the mass is spread over
    the cell's nodes), but the best of them is shorter than two elements, which the mesh does not
    tell from a point, so it is not walked out to a line of two elements or more (it had become a
    26-31 mm line: the 18 g point mass of hold-out ``ho_mass_card`` had become a 15 mm one on 6.75
    mm elements the same way); the mass stays a point at its place, its mass within 6 %."""
    from pcbdyn.diagnosis.point_mass import MASS

    m, layout = card
    xy = np.array([0.0733, 0.0836])
    half = 0.0065 * np.array([np.cos(np.deg2rad(angle)), np.sin(np.deg2rad(angle))])
    f_test = solve_modes(dg.add_effect(m, KIND.across(layout, xy - half, xy + half), 0.020), n_modes=N_MODES).frequencies
    cands = list(dg.generate(layout, kinds=["point_mass"]))
    near = min(range(len(cands)), key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], xy)))
    cands.append(MASS.at_point(layout, cands[near], xy))
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[-1]], [0.020], 8)
    sel = Selection(chosen=[len(cands) - 1], values=fit.values, p=fit.p, chi2=[fit.chi2],
                    criterion=[fit.chi2 + penalty(res.n_rows, len(cands))], state=fit.state)
    sel = as_lines(res, cands, sel, 0.02, layout, 0.0065)
    assert [cands[i].kind for i in sel.chosen] == ["point_mass"]
    assert np.allclose(cands[sel.chosen[0]].at[:2], xy)
    assert sel.values[0] == pytest.approx(0.020, rel=0.06)

def _region_selection(m, layout, f_test, centre, mass):
    """The region mass of the catalogue's patch whose centre lies nearest ``centre`` (x, y) [m], fitted to
    ``f_test`` from ``mass`` [kg], then :func:`as_lines` on it: (candidates, the region's index, its fit,
    the selection after, the penalty)."""
    cands = list(dg.generate(layout, kinds=["region_mass"]))
    near = min(range(len(cands)), key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], centre)))
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[near]], [mass], 8)
    pen = penalty(res.n_rows, len(cands))
    sel = Selection(chosen=[near], values=fit.values, p=fit.p, chi2=[fit.chi2], criterion=[fit.chi2 + pen],
                    state=fit.state)
    return cands, near, fit, as_lines(res, cands, sel, 0.02, layout, 0.0065), pen


def test_a_region_mass_standing_in_for_a_line_becomes_the_line(card):
    """The 12 g line found as a mass over the patch of the regions' grid nearest its centre (the search's
    other spread mass): tried as lines through that patch's centre and walked, it becomes the line, its
    mass within 5 %, its ends within 15 mm, its frequencies fitted within the noise and better than the
    patch's by more than the penalty a line's direction and length pay."""
    m, layout = card
    f_test = solve_modes(dg.add_effect(m, KIND.across(layout, *ENDS), 0.012), n_modes=N_MODES).frequencies
    cands, near, fit, sel, pen = _region_selection(m, layout, f_test, ENDS.mean(axis=0), 0.012)
    assert [cands[i].kind for i in sel.chosen] == ["line_mass"]
    assert np.linalg.norm(cands[sel.chosen[0]].geometry["segment"] - ENDS, axis=1).max() < 0.015
    assert sel.values[0] == pytest.approx(0.012, rel=0.05)
    assert sel.chi2[-1] < N_MODES and sel.chi2[-1] + pen < fit.chi2


def test_a_mass_over_a_region_stays_a_region(card):
    """A 30 g mass spread over a 40 mm patch (a shield can), found on that patch: no line through it fits
    the frequencies better by a line's extra penalty, and the region stays with its mass."""
    m, layout = card
    cands = list(dg.generate(layout, kinds=["region_mass"]))
    big = [i for i, c in enumerate(cands) if np.ptp(np.asarray(c.geometry["polygon"])[:, 0]) > 0.035]
    true = min(big, key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], (0.08, 0.09))))
    f_test = solve_modes(dg.add_effect(m, cands[true], 0.030), n_modes=N_MODES).frequencies
    cands, near, fit, sel, _ = _region_selection(m, layout, f_test, cands[true].at[:2], 0.030)
    assert cands[near].name == cands[true].name and fit.chi2 < 1e-6
    assert [cands[i].kind for i in sel.chosen] == ["region_mass"] and sel.values[0] == pytest.approx(0.030, rel=1e-6)
