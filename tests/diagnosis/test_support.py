"""A support the free model lacks, shown by a measured mode of rigid-body shape (:mod:`pcbdyn.diagnosis.support`):
exact data of a free plate on one spring to ground at a point between nodes, with a mass beside it
or not. The bounce is told from the elastic modes, the spring placed from its rigid-body part and
sized from its frequency."""

from types import SimpleNamespace

import numpy as np
import pytest
from diagnosis_plates import PLATE, measured

import pcbdyn.diagnosis as dg
from pcbdyn.diagnosis.ground_spring import KIND as SPRING
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.support import locate, rigid_share, shapes_kept, support_modes
from pcbdyn.fe import MassProperty, Model
from pcbdyn.fe.generate import rectangle
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import model_probe

A, B = 0.16, 0.12


def free_plate():
    nodes, conn = rectangle(A, B, 16, 12)
    m = Model(nodes)
    m.add("plate", "quad4", conn, PLATE)
    m.free = True
    return m


@pytest.mark.parametrize("at, k, mass", [((0.0537, 0.0711), 2e4, 0.0), ((0.1213, 0.0305), 3e4, 0.01)])
def test_bounce_places_and_sizes_the_spring(at, k, mass):
    """The test's first mode, the plate bouncing on the spring, is mostly rigid-body motion at the
    points and resembles no elastic mode; its rigid part places the spring within 0.1 mm (the
    mesh: 10 mm; exact data, and a mass at the same point keeps the rigid part along the spring's) and its
    frequency sizes it within 5 % (Rayleigh-Ritz on the free model's first modes, an upper bound of
    the bounce: the spring found is a little softer than the truth). A mass on it is not yet known:
    the spring found then bounces the plate alone at that frequency, softer still (the search fits
    both)."""
    model = free_plate()
    layout = dg.from_model(model)
    point = SPRING.at_point(layout, None, at)
    truth = dg.add_effect(model, point, k)
    if mass:  # a bracket's mass on the same point
        truth.add("bracket", "mass", [point.nodes], MassProperty(mass, footprint=[point.data["point_weights"]]))
    xy = np.stack(np.meshgrid(np.linspace(0.005, A - 0.005, 9), np.linspace(0.005, B - 0.005, 7)), -1).reshape(-1, 2)
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    modes = solve_modes(truth, n_modes=5)
    shapes = np.asarray(model_probe(truth, xyz).P @ modes.shapes)
    ob = Observation(None, measured(modes.frequencies, shapes, xyz), np.full(5, 1e-3), model_probe(model, xyz).P,
                     np.full(5, 1e-2))
    cs = ModalResidual([ob], lambda p: [model]).evaluate(np.zeros(0)).configs[0]

    share = rigid_share(ob, cs)
    assert share[0] > 0.5 and np.all(share[1:] < 0.2)  # 0.99 and 0.73: the stiffer spring bends the plate
    assert support_modes(ob, cs).tolist() == [True, False, False, False, False]
    spring, value, _ = locate(ob, cs, 0, dg.generate(layout, ["ground_spring"]), layout)
    assert np.hypot(*np.subtract(spring.at, at)) < 1e-4
    if mass:  # not yet known: the spring found bounces the plate alone at the bounce's frequency
        assert 0.6 * k < value < k
    else:
        assert 0.95 * k < value <= k


def test_a_mass_is_sized_on_the_branch_of_the_mode_it_makes():
    """Three modes (eigenvalues 1, 4, 25, unit modal masses), a 1 kg mass at a point that moves most
    in the third: the mode it makes lies at 5.4, between the second and third. At a small mass the
    Rayleigh-Ritz mode most like that mode is the second, below the measured eigenvalue (the sizing
    before refused such a mass: "a mass only lowers it"); sized over the range the crossing where the
    mode is most like the measured one gives the mass exactly."""
    from scipy.linalg import eigh

    from pcbdyn.diagnosis.support import most_like, sized

    lam, points, v, truth = np.array([1.0, 4.0, 25.0]), np.eye(3), np.array([0.3, 0.6, 3.0]), 1.0
    val, vec = eigh(np.diag(lam), np.eye(3) + truth * np.outer(v, v))
    x, target = vec[:, 2:3], val[2]
    assert lam[1] < target < lam[2]
    assert most_like(lam, points, x, dM=1e-3 * np.outer(v, v))[0] < target
    mass = sized(lambda m: most_like(lam, points, x, dM=m * np.outer(v, v)), target, 1e-3, 1e2)
    assert mass == pytest.approx(truth, rel=1e-9)


def test_a_mass_sized_to_the_shape_is_exact_where_the_stiffness_is_off_by_a_factor():
    """The three modes above, the measured mode made by a 1 kg mass, the model's stiffness 21 % low
    (its frequencies 10 % low: a board's E off). A stiffness off by one factor moves every eigenvalue
    by it and leaves the shapes as they are, so the mass whose Rayleigh-Ritz mode is most like the
    measured shape is the true one (MAC 1), while the mass sized to the measured frequency is about
    half of it (beyond the 30 % the benchmark allows)."""
    from scipy.linalg import eigh

    from pcbdyn.diagnosis.support import most_like, sized
    from pcbdyn.diagnosis.unpaired import shaped

    lam, points, v, truth = np.array([1.0, 4.0, 25.0]), np.eye(3), np.array([0.3, 0.6, 3.0]), 1.0
    val, vec = eigh(np.diag(lam), np.eye(3) + truth * np.outer(v, v))
    x, target = vec[:, 2:3], val[2]
    model = lam / 1.1**2

    def ritz(m):
        return most_like(model, points, x, dM=m * np.outer(v, v))

    by_frequency = sized(ritz, target, 1e-3, 1e2)
    assert by_frequency is None or abs(by_frequency / truth - 1.0) > 0.3
    cand, mass, like = shaped(ritz, "the point", 1e-3, 1e2)
    assert cand == "the point"
    assert mass == pytest.approx(truth, rel=1e-3)
    assert like == pytest.approx(1.0, abs=1e-9)


def _pairing(mac, matched):
    return SimpleNamespace(configs=[SimpleNamespace(mac=np.array(mac), matched=np.array(matched))])


def test_an_effect_that_takes_a_well_paired_modes_partner_away_is_not_kept():
    """An effect placed to give test mode 4 a partner is kept when the modes paired before keep theirs
    about as well, and when it takes the partner of a poorly paired mode (MAC 0.45) away; one that
    leaves mode 1 (MAC 0.99) without a partner is refused, though the modes paired in both states
    resemble theirs a little better (dev seed 0); so is one that makes the others less alike."""
    before = _pairing([0.99, 0.95, 0.45, 0.20], [True, True, True, False])
    assert shapes_kept(before, _pairing([0.99, 0.95, 0.46, 0.85], [True, True, True, True]))
    assert shapes_kept(before, _pairing([0.99, 0.95, 0.10, 0.85], [True, True, False, True]))
    assert not shapes_kept(before, _pairing([0.10, 0.96, 0.46, 0.85], [False, True, True, True]))
    assert not shapes_kept(before, _pairing([0.90, 0.85, 0.40, 0.85], [True, True, True, True]))
