"""First selection on synthetic data: a hidden effect is found from frequency residuals, and
noise alone gives none."""

import numpy as np
import pytest
import shapely

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.select import forward_select
from pcbdyn.fe import MassProperty
from pcbdyn.fe.modal import solve_modes

from pcbdyn.testdata import MeasuredModes

from diagnosis_plates import guided_card

N_MODES, SIGMA = 8, 0.002  # 8 paired modes, 0.2 % frequency noise
NX, NY = 12, 14  # elements of the 160 x 180 mm card: about 13 mm
H = np.hypot(0.16 / NX, 0.18 / NY)  # element diagonal [m]


def nearest(model, x, y):
    return int(np.linalg.norm(model.nodes[:, :2] - [x, y], axis=1).argmin())


@pytest.fixture(scope="module")
def card():
    """The guided 160 x 180 mm card of :func:`diagnosis_plates.guided_card` (12 x 14 elements) with
    candidates of every kind."""
    m = guided_card(NX, NY)
    layout = dg.from_model(m, suspects={"points.exc": nearest(m, 0.04, 0.13)})
    return m, dg.generate(layout, segments=3, patch=0.04, path_spacing=0.04)


def nearest_candidate(cands, kind, xy):
    return min((c for c in cands if c.kind == kind), key=lambda c: np.hypot(c.at[0] - xy[0], c.at[1] - xy[1]))


def measured(model, effect, value, seed):
    f = solve_modes(dg.add_effect(model, effect, value) if effect else model, n_modes=N_MODES).frequencies
    return f * (1.0 + SIGMA * np.random.default_rng(seed).standard_normal(f.size))


def test_hidden_transducer_mass_at_the_excitation_point_is_found(card):
    m, cands = card
    hidden = next(c for c in cands if c.name == "point_mass@points.exc")
    sel = forward_select(m, cands, measured(m, hidden, 0.013, seed=1), SIGMA)
    assert [cands[i].name for i in sel.chosen] == ["point_mass@points.exc"]
    assert sel.values[0] == pytest.approx(0.013, rel=0.05)
    assert sel.chi2[-1] < 3 * N_MODES  # what remains is noise


@pytest.mark.parametrize("kind, xy, value", [
    ("point_mass", (0.11, 0.15), 0.013),  # a 13 g transducer away from the declared points
    ("point_mass", (0.07, 0.04), 0.013),
    ("region_stiffness", (0.06, 0.06), 0.5),  # +50 % stiffness over a 40 mm patch
    ("stiffener", (0.08, 0.11), 0.5),  # a rib across the card
    ("line_mass", (0.08, 0.18), 0.02),  # a 20 g connector along the top edge
])
def test_hidden_effect_is_found_with_its_kind_place_and_magnitude(card, kind, xy, value):
    """Right kind, within one element (the issue's 15 mm), magnitude within 30 %. (Ground springs
    and edge stiffness are not here: from 8 frequencies alone they are placed right only for some
    noise draws; they need the mode shapes.)"""
    m, cands = card
    hidden = nearest_candidate(cands, kind, xy)
    sel = forward_select(m, cands, measured(m, hidden, value, seed=3), SIGMA)
    assert len(sel.chosen) == 1
    found = cands[sel.chosen[0]]
    assert found.kind == kind
    assert np.hypot(found.at[0] - hidden.at[0], found.at[1] - hidden.at[1]) <= H * 1.001
    assert sel.values[0] == pytest.approx(value, rel=0.3)
    assert sel.chi2[-1] < 3 * N_MODES  # what remains is noise


@pytest.mark.parametrize("xy, k", [((0.05, 0.17), 3e6), ((0.13, 0.12), 1e6), ((0.03, 0.02), 1e6)])
def test_a_near_rigid_spring_is_found_at_its_node(card, xy, k):
    """A spring of 1-3e6 N/m (a screw the model lacks; the card's first mode needs ~1e4 N/m to move)
    pins its node: found at that node, its stiffness within 30 %, what remains noise. Near saturation
    the linear scores of many places are alike, so the search also screens the supports at large
    stiffness (:func:`pcbdyn.diagnosis.scan.saturated`); without that screen these three come out
    as a region 20 mm away, a spring on the next node at its bound of 1e7 N/m, two springs beside it."""
    m, cands = card
    hidden = nearest_candidate(cands, "ground_spring", xy)
    sel = forward_select(m, cands, measured(m, hidden, k, seed=3), SIGMA)
    assert [cands[i].name for i in sel.chosen] == [hidden.name]
    assert sel.values[0] == pytest.approx(k, rel=0.3)
    assert sel.chi2[-1] < 3 * N_MODES


@pytest.mark.parametrize("seed", [4, 5, 6])
def test_noise_alone_gives_no_effect(card, seed):
    m, cands = card
    sel = forward_select(m, cands, measured(m, None, 0.0, seed=seed), SIGMA)
    assert sel.chosen == []


def test_refine_moves_a_segment_found_too_short_to_the_true_run(card):
    """A line mass over two pieces of a free side, first fitted on one of them: the local search
    on the run's ends (:func:`refine` with the pipeline's neighbours) moves it to the true run and
    recovers its mass."""
    from pcbdyn.diagnosis.moves import LocalMoves
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate, refine
    from pcbdyn.diagnosis.selection import Selection

    m, cands = card
    runs = {c.data["run"]: i for i, c in enumerate(cands) if c.kind == "line_mass" and "run" in c.data}
    side = next(side for side, i, j in runs if (i, j) == (1, 2))
    truth, start = runs[(side, 1, 2)], runs[(side, 1, 1)]
    f_test = solve_modes(dg.add_effect(m, cands[truth], 0.03), n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))], lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[start]], [0.03], 8)
    assert fit.chi2 > 10.0  # the wrong run cannot explain the data
    sel = Selection(chosen=[start], values=fit.values, p=fit.p, chi2=[fit.chi2], state=fit.state)
    sel = refine(res, cands, sel, LocalMoves(dg.from_model(m), cands, 0.01))
    assert [cands[i].name for i in sel.chosen] == [cands[truth].name]
    assert sel.values[0] == pytest.approx(0.03, rel=1e-3)
    assert sel.chi2[-1] < 1e-3


def test_refine_walks_a_point_mass_placed_nodes_away_to_its_node(card):
    """A 20 g mass first fitted two elements across and one along from where it sits (as a mass placed
    from a mode without a partner at wrong starting parameters is): the local search moves it node by
    node (:class:`LocalMoves`, the eight nodes around) to its node and recovers its mass."""
    from pcbdyn.diagnosis.moves import LocalMoves, on_node
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate, refine
    from pcbdyn.diagnosis.selection import Selection

    m, cands = card
    cands = list(cands)
    dx, dy = 0.16 / NX, 0.18 / NY
    truth = cands.index(nearest_candidate(cands, "point_mass", (0.11, 0.12)))
    start = cands.index(nearest_candidate(cands, "point_mass", (0.11 - 2 * dx, 0.12 + dy)))
    assert on_node(cands[start]) and np.hypot(*np.subtract(cands[start].at, cands[truth].at)[:2]) > 2 * dx
    f_test = solve_modes(dg.add_effect(m, cands[truth], 0.02), n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))], lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[start]], [0.02], 8)
    assert fit.chi2 > 10.0  # the wrong node cannot explain the data
    sel = Selection(chosen=[start], values=fit.values, p=fit.p, chi2=[fit.chi2], state=fit.state)
    sel = refine(res, cands, sel, LocalMoves(dg.from_model(m), cands, dx))
    assert cands[sel.chosen[0]].nodes.tolist() == cands[truth].nodes.tolist()
    assert sel.values[0] == pytest.approx(0.02, rel=1e-3)
    assert sel.chi2[-1] < 1e-3


def test_a_mass_with_an_inertia_beside_it_is_refitted_as_one_body(card):
    """A 40 g part of 10 mm radius of gyration centred between two nodes, first fitted as two mass
    shares on those nodes and an inertia alone on one of them: :func:`as_bodies` makes them one
    body, moving with its disc, placed where the data put it (the shares' centre is 0.8 mm off; the
    body's is within half the finest step of its pattern search, 0.23 mm) and recovers m and J
    (the radius is a fixed point of the fit) to what a centre that far off leaves: 0.5 % and 1 %,
    chi^2 a fiftieth of the pair's (0.13 mm, 0.4 %, a 260th on main; 0.22 mm, 0.6 %, a 75th since
    an inertia alone moves with a disc of fixed size)."""
    from pcbdyn.diagnosis.bodies import as_bodies
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate
    from pcbdyn.diagnosis.selection import Selection, penalty
    from pcbdyn.fixtures.supports import disc_footprint

    m, cands = card
    a, b = nearest(m, 0.09, 0.11), nearest(m, 0.09 + 0.16 / NX, 0.11)
    centre = 0.5 * (m.nodes[a] + m.nodes[b])
    shells = [(s.etype, s.conn) for s in m.sets.values() if s.etype == "quad4"]
    conn, W = disc_footprint(m.nodes, shells, centre, 0.01)
    truth = m.copy()
    truth.add("part", "mass", [conn], MassProperty(0.04, (4e-6, 4e-6, 0.0), footprint=W))
    f_test = solve_modes(truth, n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))], lambda p: [m])
    by_name = {c.name: i for i, c in enumerate(cands)}
    start = [by_name[f"point_mass@n{a}"], by_name[f"point_mass@n{b}"], by_name[f"point_inertia@n{a}"]]
    fit = estimate(res, np.zeros(0), [cands[i] for i in start], [0.02, 0.02, 2e-6], 8)
    sel = Selection(chosen=start, values=fit.values, p=fit.p, chi2=[fit.chi2], criterion=[fit.chi2 + 3 * penalty(N_MODES, len(cands))],
                    state=fit.state)
    cands = list(cands)
    sel = as_bodies(res, cands, sel, [[0, 1], [2]], reach=2 * H)
    assert [(cands[i].kind, cands[i].name.startswith("body@")) for i in sel.chosen] == [
        ("point_mass", True), ("point_inertia", True)]
    print('DBG', cands[sel.chosen[0]].at, centre[:2], sel.values, sel.chi2[-1], fit.chi2)
    finest = 2 * H / 10 / 8  # the centre's pattern search: from reach / 10 down to an eighth of it
    assert np.abs(np.subtract(cands[sel.chosen[0]].at, centre[:2])).max() < finest / 2
    assert sel.values[0] == pytest.approx(0.04, rel=0.005)
    assert sel.values[1] == pytest.approx(4e-6, rel=0.01)
    assert sel.chi2[-1] < 2e-2 * fit.chi2


def test_refine_walks_a_region_found_on_the_patch_grid_to_the_true_rectangle(card):
    """A stiffened rectangle off the patch grid, first fitted on the patch that overlaps it most:
    moving one side by one element at a time (:class:`LocalMoves`) reaches the true rectangle and
    its stiffness change."""
    from pcbdyn.diagnosis.moves import LocalMoves, rectangle
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate, refine
    from pcbdyn.diagnosis.selection import Selection

    m, cands = card
    layout = dg.from_model(m)
    step = 0.16 / NX
    truth = dg.kind("region_stiffness").rectangle(layout, 3 * step, 4 * 0.18 / NY, 7 * step, 9 * 0.18 / NY)
    f_test = solve_modes(dg.add_effect(m, truth, 1.5), n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))], lambda p: [m])
    cands = list(cands)
    patches = [i for i, c in enumerate(cands) if c.kind == "region_stiffness" and rectangle(c) is not None]
    start = min(patches, key=lambda i: np.hypot(*np.subtract(cands[i].at, truth.at)))
    fit = estimate(res, np.zeros(0), [cands[start]], [1.0], 8)
    assert fit.chi2 > 10.0  # the patch cannot explain the data
    sel = Selection(chosen=[start], values=fit.values, p=fit.p, chi2=[fit.chi2], state=fit.state)
    sel = refine(res, cands, sel, LocalMoves(layout, cands, step))
    found = cands[sel.chosen[0]]
    assert np.array_equal(found.nodes, truth.nodes)  # the same cells
    assert sel.values[0] == pytest.approx(1.5, rel=1e-3)


def test_held_out_share_tells_an_effect_every_fold_sees_from_one_fitted_to_one_fold():
    """Cross-validation over folds (:func:`held_out_share`): a column that shapes the residual of
    every mode predicts each left-out mode; one that matches a single mode's error (beside what
    the held columns explain) predicts none of the others."""
    from pcbdyn.diagnosis.held_out import held_out_share

    class Rows:  # one configuration: the folds are its modes
        def row_groups(self):
            return np.zeros(80, int), np.repeat(np.arange(8), 10)

    rng = np.random.default_rng(0)
    held = rng.standard_normal((80, 2))
    effect = rng.standard_normal(80)
    noise = rng.standard_normal(80)
    assert held_out_share(Rows(), 30.0 * effect + held @ [1.0, -2.0] + noise, held, effect) == 1.0
    mode3 = np.repeat(np.arange(8), 10) == 3
    local = np.where(mode3, rng.standard_normal(80), 0.0)
    held[mode3] = 0.0  # an error of mode 3 alone, beside what the held columns explain
    assert held_out_share(Rows(), 30.0 * local + noise, held, local) == 0.0


def test_parallel_stiffeners_side_by_side_are_reported_as_one_rib(card):
    """Two parallel ribs within reach are one rib fitted as shares: their stiffnesses add and the
    path lies between them, weighted; a crossing rib stays apart."""
    from pcbdyn.diagnosis.merge import groups, merged

    m, cands = card
    layout = dg.from_model(m)
    rib = dg.kind("stiffener")
    a = rib.candidate(layout, None, np.array([0.06, 0.0]), np.array([0.06, 0.18]))
    b, cross = rib.parallel(layout, a, [0.01])[0], rib.candidate(layout, None, np.array([0.0, 0.09]),
                                                                    np.array([0.16, 0.09]))
    groups = groups([a, b, cross], 0.02)
    assert sorted(map(sorted, groups)) == [[0, 1], [2]]
    d = merged([a, b, cross], np.array([3.0, 1.0, 2.0]), np.zeros((0, 0)), np.zeros((3, 3)), np.zeros((3, 3)), [0, 1])
    assert d["magnitude"] == pytest.approx(4.0)
    assert np.allclose(np.asarray(d["path_mm"])[:, 0], 62.5)


def test_overlapping_regions_are_reported_as_one_with_their_mean_change(card):
    """Two overlapping rectangles fitted to one stiffened region are one effect: the area they
    cover (their union, not its bounding box), with the mean change over it, so that the change's
    integral over the board is what the two add."""
    from pcbdyn.diagnosis.merge import groups, merged
    from pcbdyn.diagnosis.uncertainty import model_form

    m, _ = card
    layout = dg.from_model(m)
    region = dg.kind("region_stiffness")
    a, b = region.rectangle(layout, 0.02, 0.02, 0.06, 0.06), region.rectangle(layout, 0.04, 0.04, 0.08, 0.08)
    far = region.rectangle(layout, 0.10, 0.10, 0.14, 0.14)
    assert sorted(map(sorted, groups([a, b, far], 0.02))) == [[0, 1], [2]]
    d = merged([a, b], np.array([2.0, 1.0]), np.zeros((0, 0)), np.zeros((2, 2)), np.zeros((2, 2)), [0, 1])
    union = shapely.Polygon(d["polygon_mm"])
    assert union.bounds == pytest.approx((20.0, 20.0, 80.0, 80.0))
    assert union.area == pytest.approx(2 * 40.0**2 - 20.0**2)
    assert not union.contains(shapely.Point(70.0, 30.0))  # a corner of the bounding box neither covers
    assert d["magnitude"] * union.area == pytest.approx((2.0 + 1.0) * 40.0**2)
    assert d["at_mm"] == pytest.approx([50.0, 50.0])
    assert d["uncertainty_parts"]["model_form"] == pytest.approx(model_form("region_stiffness") * d["magnitude"])


def test_distances_to_segments_used_to_merge_effects():
    """Point-to-segment and segment-to-segment distances (merging effects found side by side)."""
    from pcbdyn.diagnosis.merge import _segment_gap, _to_segment

    s = np.array([[0.0, 0.0], [1.0, 0.0]])
    for p, want in (([0.5, 2.0], 2.0), ([-3.0, 4.0], 5.0), ([1.5, 0.0], 0.5), ([0.3, 0.0], 0.0)):
        assert _to_segment(np.array(p), s) == pytest.approx(want, abs=1e-12)
    assert _segment_gap(s, np.array([[2.0, 1.0], [3.0, 1.0]])) == pytest.approx(np.sqrt(2.0), abs=1e-12)
    assert _segment_gap(s, np.array([[0.5, -1.0], [0.5, 1.0]])) == 0.0


@pytest.mark.parametrize("kinds, xy, values", [
    (("region_stiffness", "region_mass"), (0.10, 0.12), (3.0, 0.04)),  # a heat sink: 4x as stiff, 40 g
    # a stiff light sink in a corner: neither first-order prediction of the left-out modes keeps its mass
    # beside its stiffness, the folds' refits do (:func:`.held_out.refit_predicts`; before: the stiffness
    # alone, 6.1, chi^2 167 left)
    (("region_stiffness", "region_mass"), (0.05, 0.05), (8.0, 0.02)),
    (("point_mass", "ground_spring"), (0.11, 0.15), (0.015, 3e4)),  # a bracket: 15 g held by a spring
    # brackets whose own mode (356 and 280 Hz) falls among the card's (183-1310 Hz): no first-order prediction
    # of the left-out modes follows them (before the folds' refits, :func:`.held_out.refit_share`: nothing
    # reported, chi^2 7071 and 2258 left)
    (("point_mass", "ground_spring"), (0.05, 0.07), (0.02, 1e5)),
    (("point_mass", "ground_spring"), (0.05, 0.07), (0.011, 3.4e4)),
])
def test_a_body_of_two_effects_at_one_place_is_found_as_both(card, kinds, xy, values):
    """A heat sink (a region stiffer and heavier) and a bracket (a mass on a spring at one point): each
    effect alone explains the frequencies so poorly that forward selection one effect at a time takes
    neither (checked with the pairs switched off: nothing found in two of these, a 10 g mass on the
    next node in the other); tried as one addition of two (:class:`pcbdyn.diagnosis.halves.Halves`),
    both are found at their place, their magnitudes within 30 %, and what remains is noise. (From eight
    frequencies alone a region's stiffness and mass trade off: a sink twice as stiff with 25 g at
    (60, 60) mm is found at its place as 0.58 +- 0.16 and 20.5 +- 1.9 g.)"""
    m, cands = card
    a = nearest_candidate(cands, kinds[0], xy)
    b = next(c for c in cands if c.kind == kinds[1] and np.array_equal(c.nodes, a.nodes))
    f = solve_modes(dg.add_effect(dg.add_effect(m, a, values[0]), b, values[1]), n_modes=N_MODES).frequencies
    f *= 1.0 + SIGMA * np.random.default_rng(3).standard_normal(f.size)
    sel = forward_select(m, cands, f, SIGMA)
    assert sorted(cands[i].name for i in sel.chosen) == sorted([a.name, b.name])
    found = dict(zip((cands[i].kind for i in sel.chosen), sel.values))
    assert [found[k] for k in kinds] == pytest.approx(list(values), rel=0.3)
    assert sel.chi2[-1] < 3 * N_MODES


def test_refine_walks_a_heat_sink_found_on_the_patch_grid_to_its_rectangle_as_one_body(card):
    """A heat sink (a region 4x as stiff carrying 30 g) off the patch grid, first fitted as the stiffness
    and mass of the patch that overlaps it most: both halves move together (one body), side by side one
    element at a time, to the true rectangle, with both magnitudes."""
    from pcbdyn.diagnosis.moves import LocalMoves, rectangle
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.select import estimate, refine
    from pcbdyn.diagnosis.selection import Selection

    m, cands = card
    layout = dg.from_model(m)
    step = 0.16 / NX
    box = (3 * step, 4 * 0.18 / NY, 7 * step, 9 * 0.18 / NY)
    stiff, mass = (dg.kind(k).rectangle(layout, *box) for k in ("region_stiffness", "region_mass"))
    f_test = solve_modes(dg.add_effect(dg.add_effect(m, stiff, 3.0), mass, 0.03), n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))], lambda p: [m])
    cands = list(cands)
    patches = [i for i, c in enumerate(cands) if c.kind == "region_stiffness" and rectangle(c) is not None]
    start = min(patches, key=lambda i: np.hypot(*np.subtract(cands[i].at, stiff.at)))
    half = next(i for i, c in enumerate(cands) if c.kind == "region_mass" and np.array_equal(c.nodes, cands[start].nodes))
    fit = estimate(res, np.zeros(0), [cands[start], cands[half]], [1.0, 0.01], 8)
    assert fit.chi2 > 10.0  # the patch cannot explain the data
    sel = Selection(chosen=[start, half], values=fit.values, p=fit.p, chi2=[fit.chi2], state=fit.state)
    sel = refine(res, cands, sel, LocalMoves(layout, cands, step))
    found = [cands[i] for i in sel.chosen]
    assert [c.kind for c in found] == ["region_stiffness", "region_mass"]
    assert all(np.array_equal(c.nodes, stiff.nodes) for c in found)  # the same cells, both
    assert sel.values == pytest.approx([3.0, 0.03], rel=1e-3)


def test_a_spring_that_pins_the_plate_is_not_dropped_for_its_standard_deviation(card):
    """A spring to ground at the kind's bound (rigid) has a standard deviation far above its stiffness (the
    frequencies no longer change with it) and is far from no spring: ``without_vanished`` keeps it (its
    removal is weighed by chi^2, :func:`pcbdyn.diagnosis.select.noticed`)."""
    from pcbdyn.diagnosis.select import without_vanished
    from pcbdyn.diagnosis.selection import Selection

    _, cands = card
    spring = next(i for i, c in enumerate(cands) if c.kind == "ground_spring")
    sel = Selection(chosen=[spring], values=np.array([1e7]), sigma=np.array([3e7]), p=np.zeros(0))
    assert without_vanished(None, cands, sel) is sel and sel.chosen == [spring]



def test_a_selection_is_within_the_noise_by_the_chi_square_test_on_the_rows_its_fit_leaves_free():
    """:meth:`Selection.within_noise` (thesis section 5.2.3): 100 rows less 3 declared parameters and the 2
    effects chosen leave 95 degrees of freedom. A chi^2 between the 1 % points of 95 and 97 degrees lies
    beyond the noise at 95 (it would pass if the effects were not counted); the median of 95 passes."""
    from scipy.stats import chi2 as chi2_dist

    from pcbdyn.diagnosis.selection import Selection

    between = 0.5 * (chi2_dist.isf(0.01, 95) + chi2_dist.isf(0.01, 97))
    assert chi2_dist.sf(between, 97) > 0.01 > chi2_dist.sf(between, 95)
    assert not Selection(chosen=[4, 7], chi2=[3e3, between]).within_noise(97, alpha=0.01)
    assert Selection(chosen=[4, 7], chi2=[3e3, chi2_dist.median(95)]).within_noise(97, alpha=0.01)
    assert Selection(chosen=[], chi2=[between]).within_noise(95 + 2, alpha=0.01)


def test_an_effect_whose_size_the_data_cannot_tell_from_none_is_listed_apart():
    """A 13 g mass hidden on the guided card, fitted beside a spurious mass one row from a guide: the
    spurious one's reported standard deviation (its places walked, the model form) exceeds its size, so
    it is left out of the model and listed apart (issue 37: nothing reported that the data do not
    resolve); the real mass, refitted alone, keeps its size."""
    from pcbdyn.diagnosis.fitting import estimate
    from pcbdyn.diagnosis.merge import MERGE_REACH, resolved
    from pcbdyn.diagnosis.moves import LocalMoves
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.selection import Selection, adopt, penalty

    m = guided_card(NX, NY)
    layout = dg.from_model(m)
    cands = dg.generate(layout, segments=3, patch=0.04, path_spacing=0.04)
    real, edge = (cands.index(nearest_candidate(cands, "point_mass", xy)) for xy in ((0.11, 0.15), (0.0, 0.09)))
    assert cands[edge].at[0] < 0.16 / NX + 1e-9  # the row beside the guide at x = 0
    f = measured(m, cands[real], 0.013, seed=3)
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(f.size, SIGMA))], lambda p: [m])
    pen = penalty(res.n_rows, len(cands))
    sel = adopt(Selection(), [real, edge], estimate(res, [], [cands[real], cands[edge]], [0.01, 0.005], 8), pen)
    sel, effects, apart = resolved(res, cands, sel, LocalMoves(layout, cands, H).around, MERGE_REACH * H, None, pen)
    assert sel.chosen == [real]
    assert [e["type"] for e in apart] == ["point_mass"] and apart[0]["at_mm"][0] < 1e3 * 0.16 / NX + 1e-6
    assert apart[0]["uncertainty"] >= apart[0]["magnitude"]
    assert len(effects) == 1 and effects[0]["uncertainty"] < effects[0]["magnitude"]
    assert sel.values[0] == pytest.approx(0.013, rel=0.05)


@pytest.mark.parametrize("kind, xy, value", [("stiffener", (0.08, 0.11), 0.5), ("point_mass", (0.11, 0.15), 0.013)])
def test_the_trial_ranking_re_solves_every_rib_and_picks_the_one_every_re_solve_would(card, kind, xy, value):
    """:class:`pcbdyn.diagnosis.scan.Ranking` re-solves every trial a reanalysis does not follow (ribs) and of the
    others only those whose fit on the reanalysis could still be the best: of single additions of every kind
    it picks the trial that full fits of all of them rank first, and the true effect; with a rib hidden, its
    full fit leaves no other kind's quick fit within reach, so none of those is re-solved."""
    from pcbdyn.diagnosis.residual import ModalResidual, Observation
    from pcbdyn.diagnosis.fitting import RANK_STEPS
    from pcbdyn.diagnosis.scan import FULL_RANK, Ranking, Runner, _followed, _full_fit, _screen
    from pcbdyn.diagnosis.select import estimate

    m, cands = card
    hidden = nearest_candidate(cands, kind, xy)
    f_test = measured(m, hidden, value, seed=3)
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f_test), np.full(N_MODES, SIGMA))],
                        lambda p: [m])
    base = estimate(res, np.zeros(0), [], [], 8)
    near = sorted(range(len(cands)), key=lambda i: np.hypot(cands[i].at[0] - xy[0], cands[i].at[1] - xy[1]))
    picked = [i for k in ("stiffener", "point_mass", "region_stiffness", "line_mass")
              for i in [j for j in near if cands[j].kind == k][:6]]
    trials = [([cands[i]], np.array([cands[i].spec.scale])) for i in picked]
    ranking = Ranking(res, base.state, trials, np.zeros(0), None, np.zeros((res.n_rows, 0)))
    first = ranking.next()
    quick = np.asarray(_screen(res, base.state, trials, np.zeros(0), None, np.zeros((res.n_rows, 0)), RANK_STEPS))
    followed = [k for k, (c, _) in enumerate(trials) if _followed(base.state, c)]
    eligible = sorted(k for k in followed if quick[k] <= np.sort(quick[followed])[FULL_RANK - 1]) + \
        [k for k in range(len(trials)) if k not in followed]
    every = Runner().map(_full_fit, [(trials[k][0], trials[k][1], np.zeros(0)) for k in eligible],
                         (res, None, np.zeros((res.n_rows, 0))))
    assert first == eligible[int(np.argmin([chi2 for chi2, _, _ in every]))]
    assert cands[picked[first]].name == hidden.name
    resolved = {k for k, f in enumerate(ranking.fits) if f is not None}
    assert set(range(len(trials))) - set(followed) <= resolved
    assert all(ranking.quick[k] - ranking.reach >= ranking.criterion(first) for k in set(eligible) - resolved)
    assert kind != "stiffener" or resolved.isdisjoint(followed)


def test_the_ranking_re_solves_the_single_addition_that_pairs_beat_on_chi2_alone(monkeypatch):
    """The trials a reanalysis follows that a ranking may re-solve are the FULL_RANK best by quick criterion
    (chi^2 plus the penalties of what each adds): four pairs of lower chi^2, each paying a second penalty, do
    not crowd out the single addition of least criterion, which the ranking then picks (quick and full fits
    agree here, so the pick is the least criterion of all)."""
    from types import SimpleNamespace

    from pcbdyn.diagnosis import scan

    pen = 10.0
    chi2 = np.array([100.0, 95.0, 96.0, 97.0, 98.0])  # a single addition, then four pairs
    monkeypatch.setattr(scan, "_followed", lambda state, cands: True)
    monkeypatch.setattr(scan, "_screen", lambda res, state, trials, *args: [chi2[c[0]] for c, _ in trials])

    class Resolves:
        def map(self, fn, jobs, shared, what=""):
            return [(chi2[c[0]], np.zeros(1), np.zeros(0)) for c, _, _ in jobs]

    trials = [([k], np.zeros(1)) for k in range(chi2.size)]
    ranking = scan.Ranking(None, SimpleNamespace(chi2=200.0), trials, np.zeros(0), None, None, Resolves(),
                           cost=pen * np.array([1, 2, 2, 2, 2]))
    assert ranking.next() == 0
    assert ranking.criterion(0) == pytest.approx(110.0)
