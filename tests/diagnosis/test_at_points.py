"""A point mass or a spring to ground found on a node placed at its point between the nodes
(:mod:`pcbdyn.diagnosis.at_points`)."""

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.at_points import as_points
from pcbdyn.diagnosis.catalogue import kind as spec
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.select import estimate
from pcbdyn.diagnosis.selection import Selection, penalty
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import MeasuredModes

from diagnosis_plates import guided_card

N_MODES, SIGMA = 8, 0.002


@pytest.fixture(scope="module")
def card():
    """The guided card of :func:`diagnosis_plates.guided_card` (13 mm elements) and its layout."""
    m = guided_card()
    return m, dg.from_model(m)


@pytest.mark.parametrize("xy", [(0.0733, 0.0836), (0.10, 0.13)])
@pytest.mark.parametrize("kind, value", [("point_mass", 0.020), ("ground_spring", 3e4)])
def test_an_effect_found_on_a_node_is_placed_at_its_point(card, kind, value, xy):
    """A 20 g point mass or a 30 kN/m spring to ground inside a cell, found on the nearest node (that
    moves: the guides' nodes do not): placed between the nodes by :func:`as_points`, it lands within
    2 mm of its point with its magnitude within 3 %, and fits the frequencies better than the node's
    effect did. (Beside a guide the frequencies cannot place a mass: across the element next to the
    edge the modes are linear in x, and a mass m at x is the mass m (x / x')^2 at x'.)"""
    m, layout = card
    cands = list(dg.generate(layout, kinds=[kind]))
    moving = [i for i, c in enumerate(cands) if c.at[0] > 1e-6]
    near = min(moving, key=lambda i: np.linalg.norm(np.subtract(cands[i].at[:2], xy)))
    truth = dg.add_effect(m, spec(kind).at_point(layout, cands[near], xy), value)
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(solve_modes(truth, n_modes=N_MODES).frequencies),
                                     np.full(N_MODES, SIGMA))], lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[near]], [value], 8)
    sel = Selection(chosen=[near], values=fit.values, p=fit.p, chi2=[fit.chi2],
                    criterion=[fit.chi2 + penalty(res.n_rows, len(cands))], state=fit.state)
    sel = as_points(res, cands, sel, 0.02, layout, 0.0065)
    placed = cands[sel.chosen[0]]
    assert placed.kind == kind and sel.chosen[0] != near
    assert np.linalg.norm(np.subtract(placed.at[:2], xy)) < 0.002
    assert sel.values[0] == pytest.approx(value, rel=0.03)
    assert sel.chi2[-1] < fit.chi2


def test_springs_on_a_node_on_an_edge_and_in_a_cell_are_derived_together_as_alone(card):
    """Springs to ground at a node, at a point on a cell's edge (two nodes) and inside a cell (four)
    asked for at once (as the evidence map asks for every spring the walks made): each one's dK/dk is
    the one it has alone, and a unit force at the point is shared by the nodes' weights (they sum to 1)."""
    from pcbdyn.diagnosis.catalogue import derivatives

    m, layout = card
    on_node = dg.generate(layout, kinds=["ground_spring"])[40]
    x, y = on_node.at[:2]
    dx, dy = 0.16 / 12, 0.18 / 14
    made = [on_node] + [spec("ground_spring").at_point(layout, on_node, p) for p in ((x + dx / 3, y), (x + dx / 3, y + dy / 4))]
    assert [c.nodes.size for c in made] == [1, 2, 4]
    together = dg.KINDS["ground_spring"].blocks(m, made)
    assert sorted(b.conn.shape[1] for b in together) == [1, 2, 4]
    for b in together:
        for row, k in enumerate(b.owner):
            K, _ = derivatives(m, made[k])
            dofs = (6 * b.conn[row][:, None] + np.arange(6)).ravel()
            assert np.allclose(K[np.ix_(dofs, dofs)].toarray(), b.Ke[row])
    assert sum(made[2].data["point_weights"]) == pytest.approx(1.0)


def test_a_mass_and_a_spring_found_on_nodes_are_each_placed_at_their_point(card):
    """A 20 g mass and a 30 kN/m spring to ground, each inside a cell and found on its nearest node: both
    are placed at their points, each as its own kind. Placing the first re-orders the effects chosen, and the
    second used to be looked up at its old position: here that named the mass just placed, which a spring
    could not replace, so the spring stayed on its node; on discovery report seed 1020 (a bracket beside a
    mass, three effects) the position was past the end, an IndexError that stopped the diagnosis."""
    m, layout = card
    truth = [("point_mass", (0.0733, 0.0836), 0.020), ("ground_spring", (0.10, 0.13), 3e4)]
    cands, near, model = [], [], m
    for kind, xy, value in truth:
        own = [c for c in dg.generate(layout, kinds=[kind]) if c.at[0] > 1e-6]
        home = min(own, key=lambda c: np.linalg.norm(np.subtract(c.at[:2], xy)))
        near.append(len(cands) + own.index(home))
        cands += own
        model = dg.add_effect(model, spec(kind).at_point(layout, home, xy), value)
    f = solve_modes(model, n_modes=N_MODES).frequencies
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(N_MODES, SIGMA))], lambda p: [m])
    fit = estimate(res, np.zeros(0), [cands[i] for i in near], [v for *_, v in truth], 8)
    sel = Selection(chosen=list(near), values=fit.values, p=fit.p, chi2=[fit.chi2],
                    criterion=[fit.chi2 + 2 * penalty(res.n_rows, len(cands))], state=fit.state)
    sel = as_points(res, cands, sel, 0.02, layout, 0.0065)
    placed = {cands[i].kind: (cands[i], v) for i, v in zip(sel.chosen, sel.values)}
    assert sorted(placed) == ["ground_spring", "point_mass"] and not set(sel.chosen) & set(near)
    for kind, xy, value in truth:
        c, v = placed[kind]
        assert np.linalg.norm(np.subtract(c.at[:2], xy)) < 0.002
        assert v == pytest.approx(value, rel=0.03)
    assert sel.chi2[-1] < fit.chi2


@pytest.mark.parametrize("kind", ["point_mass", "ground_spring"])
def test_a_point_walked_just_past_an_edge_is_placed_on_it_on_any_mesh(card, kind):
    """A point 0.7 mm past the edge x = 160 mm lies on the card's 13 mm cells to the locator's tolerance (a
    tenth of a cell) but off the 3.3 mm cells of a mesh four times finer: the effect is placed on the edge,
    and goes onto the finer mesh at that point (a spring walked past the edge stopped the mesh correction's
    solve of hold-out ho_transducer_cfg); a point 2 mm past the edge is off the card."""
    m, layout = card
    home = next(c for c in dg.generate(layout, kinds=[kind]) if c.at[0] > 1e-6)
    c = spec(kind).at_point(layout, home, (0.1607, 0.07))
    assert c.at[:2] == pytest.approx((0.16, 0.07), abs=1e-12)
    fine = guided_card(48, 56)
    moved = dg.add_effect(fine, spec(kind).place(dg.from_model(fine), c), 0.02 if kind == "point_mass" else 3e4)
    assert len(moved.sets) == len(fine.sets) + 1
    assert spec(kind).at_point(layout, home, (0.162, 0.07)) is None
