"""K(p), M(p) and their derivatives without re-assembly (:mod:`pcbdyn.fe.parametric_matrices`), on the
six-part card (four parameters: three part thicknesses, which enter the shell's bending stiffness
as t^3, and the laminate's E, which enters linearly): the interpolated sets equal a model built at
the same values, and their derivatives equal central differences of such builds."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcbdyn.board.board import load_board
from pcbdyn.fe.assembly import assemble
from pcbdyn.problems.models import StructureModels

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "six_part_card" / "board.toml"


@pytest.fixture(scope="module")
def models():
    return StructureModels(load_board(EXAMPLE), [None], mesh_size=10e-3, shared_mesh=True)


def relative(a, b) -> float:
    return float(abs(a - b).max() / abs(b).max())


def test_interpolated_equals_assembled(models):
    """K and M of the interpolated sets equal a model built at the same values (t^3 is interpolated
    exactly by the cubic grid), away from the declared values and at them."""
    p0 = models.p0.copy()
    p1 = p0 * np.array([1.31, 0.83, 1.12, 0.91])
    pmx = models.parametric[0]
    assert all(s.coef is not None for s in pmx.sets), "every set of the card is interpolated"
    built0, built1 = (assemble(models.build(p)[0]) for p in (p0, p1))
    for got, (k, m) in ((pmx.matrices(p0), built0), (pmx.matrices(p1), built1)):
        assert relative(got[0], k) < 1e-8
        assert relative(got[1], m) < 1e-8


def test_derivatives_match_central_differences(models):
    """dK/dp and dM/dp of each parameter (exact, from the interpolant) equal central differences of
    models built at p +- h; M does not depend on E."""
    p = models.p0 * np.array([1.2, 0.9, 1.05, 1.1])
    d = models.parametric[0].derivatives(p)
    for j in range(p.size):
        h = 1e-4 * p[j]
        up, down = p.copy(), p.copy()
        up[j] += h
        down[j] -= h
        for got, a, b in zip(d[j], assemble(models.build(up)[0]), assemble(models.build(down)[0])):
            fd = (a - b) / (2 * h)
            # round-off of the differences: 1e-13 of the matrix over the step
            assert abs(got - fd).max() <= 1e-5 * abs(fd).max() + 1e-13 * abs(a).max() / h, models.names[j]


def test_a_degree_learned_too_low_falls_back_to_the_full_grid(models):
    """E enters linearly (its own set, the laminate, shows it), so the parts' sets are interpolated on
    two points along E; a part's thickness taken as linear too (it enters the bending as t^3) is
    refused by the check and the full cubic grid gives the set, equal to an assembly off every node."""
    from pcbdyn.fe.parametric_matrices import DEGREE, ParametricMatrices

    pmx = models.parametric[0]
    e = models.names.index("E_board")
    assert pmx._degree[e] == 1
    part = next(s for s in pmx.sets if len(s.js) == 2)
    t = next(j for j in part.js if j != e)
    fresh = ParametricMatrices(models.models[0], models.names)
    fresh._degree = {e: 1, t: 1}
    s = fresh._interpolated(part.name, part.js, part.pos, [None, None])
    assert s.coef is not None and s.exps[:, part.js.index(t)].max() == DEGREE
    x = np.zeros(len(models.names))
    x[part.js] = (-0.41, 0.63)
    direct = fresh._direct(part.name, fresh.centre + fresh.half * x)
    assert np.abs(s.values(x) - direct).max() <= 1e-9 * np.abs(direct).max()


def test_a_housing_plate_on_its_modulus_and_density_and_ribs_on_their_height():
    """The example housing's parameters: its upper plate's E (K alone) and rho (M alone), which its
    maker declares linear, and rib heights (a Timoshenko beam's shear term and a torsion constant: not
    polynomials). The plate's set is interpolated on two points per parameter, though each of its
    monomials is zero in one of the two matrices and M's entries are 1e-12 of K's on the example's mesh
    (a cut relative to the largest coefficient of either dropped rho's monomial, and the set failed its
    check); the ribs' sets are made at each call; both equal a model built at the same values."""
    from pcbdyn.box import load_box

    box = StructureModels(load_box(EXAMPLE.parents[1] / "ribbed_box" / "box.toml"), [None])
    pmx = box.parametric[0]
    by_name = {s.name: s for s in pmx.sets}
    plate = by_name["plates.upper"]
    assert plate.coef is not None and plate.exps.max() == 1 and len(plate.exps) == 3  # 1, E, rho
    assert all(s.coef is None for n, s in by_name.items() if n.startswith("ribs."))
    p1 = box.p0 * np.linspace(0.8, 1.25, box.p0.size)
    for got, built in zip(pmx.matrices(p1), assemble(box.build(p1)[0])):
        assert relative(got, built) < 1e-9
