"""The reanalysis that screens trial fits (:mod:`pcbdyn.diagnosis.reanalysis`) against full re-solves:
Rayleigh-Ritz on a state's modes and its effects' static corrections never lies below an eigenvalue
(the Ritz bound) and, for effects that act on a few DOFs, follows them closely."""

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.reanalysis import Reanalysis
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.testdata import MeasuredModes

from diagnosis_plates import guided_card

N_MODES = 8


def nearest_candidate(cands, kind, xy):
    return min((c for c in cands if c.kind == kind), key=lambda c: np.hypot(c.at[0] - xy[0], c.at[1] - xy[1]))


@pytest.fixture(scope="module")
def solved():
    """The guided card with a 20 g mass found at (50, 140) mm: its residual, candidates and solved state."""
    m = guided_card(12, 14)
    cands = dg.generate(dg.from_model(m), segments=3, patch=0.04, path_spacing=0.04)
    f = np.linspace(100.0, 800.0, N_MODES)  # the frequencies are not what is compared here
    res = ModalResidual([Observation(None, MeasuredModes.frequencies_only(f), np.full(N_MODES, 0.002))],
                        lambda p: [m])
    mass = nearest_candidate(cands, "point_mass", (0.05, 0.14))
    return res, cands, mass, res.evaluate([], [mass], [0.02])


def paired_hz(st):
    cs = st.configs[0]
    return np.asarray(cs.modes.frequencies)[cs.pairs]


@pytest.mark.parametrize("kind, xy, value", [("point_mass", (0.11, 0.06), 0.015),
                                             ("ground_spring", (0.10, 0.12), 3e4),
                                             ("ground_spring", (0.10, 0.12), 3e6)])
def test_a_local_effect_added_to_a_solved_state_follows_the_full_re_solve(solved, kind, xy, value):
    """A second effect (a mass, a spring up to one that pins its node) on the reanalysis: every
    paired frequency at or above the full re-solve's (Ritz) and within 0.05 % of it, also with the
    state's own mass moved by half; its static correction has the rank of its few DOFs' loads."""
    res, cands, mass, st = solved
    other = nearest_candidate(cands, kind, xy)
    rx = Reanalysis(res, st)
    for values in ([0.02, value], [0.03, value]):
        exact, quick = (paired_hz(r.evaluate([], [mass, other], values)) for r in (res, rx))
        assert np.all(quick >= exact * (1 - 1e-9))
        assert np.max(quick / exact - 1.0) < 5e-4
    assert rx.configs[0].X[other.name].shape[1] <= 3


def test_corrections_made_together_for_a_screen_are_those_made_one_at_a_time(solved):
    """A screen's static corrections solved in blocks (:meth:`Reanalysis.prepare`) give each trial the
    frequencies it has with its correction solved alone, to a millionth (round-off can move a direction
    across the rank cut, worth ~1e-8 here; the reanalysis itself is trusted to 5e-4): the block changes
    the cost, not the basis."""
    res, cands, mass, st = solved
    near = sorted((c for c in cands if c.kind in ("point_mass", "ground_spring", "stiffener")),
                  key=lambda c: np.hypot(c.at[0] - 0.08, c.at[1] - 0.09))[:40]
    together, alone = Reanalysis(res, st), Reanalysis(res, st)
    together.prepare(near)
    assert set(together.configs[0].X) >= {c.name for c in near}
    for c in near:
        value = 10.0 * c.spec.scale
        a, b = (paired_hz(r.evaluate([], [mass, c], [0.02, value])) for r in (together, alone))
        assert np.allclose(a, b, rtol=1e-6, atol=0.0)


def test_a_basis_pencil_is_its_blocks_products_whichever_bases_made_them_before(solved):
    """A basis's reduced matrices B^T D B (the stiffness, the mass, and a declared parameter's structure-wide
    dK, dM, for which K and 2 M stand in) are those of the basis taken whole, to round-off, after bases that
    share some of its blocks, in another order, made and kept them (:meth:`_Config._gram`)."""
    res, cands, mass, st = solved
    near = sorted((c for c in cands if c.kind in ("point_mass", "ground_spring")),
                  key=lambda c: np.hypot(c.at[0] - 0.08, c.at[1] - 0.09))[:3]
    rx = Reanalysis(res, st)
    rx.prepare(near + [mass])
    cfg = rx.configs[0]
    K, M = cfg.cs.K, cfg.cs.M
    a, b, c = (n.name for n in near)
    cfg.basis([mass.name, a])
    cfg.moved_parameter(0, K, 2.0 * M, [b, mass.name])
    keys = [b, mass.name, a, c]
    B = np.column_stack([cfg.phi] + [cfg.X[k] for k in keys])
    assert B.shape[1] > cfg.phi.shape[1] + 3
    KB, MB, _, _ = cfg.basis(keys)
    for got, D in zip((KB, MB, *cfg.moved_parameter(0, K, 2.0 * M, keys)), (K, M, K, 2.0 * M)):
        want = B.T @ (D @ B)
        assert np.allclose(got, want, rtol=0.0, atol=1e-9 * np.abs(want).max())
