"""An addition worth its penalty that the held-out folds refuse is walked before it is refused
(:func:`pcbdyn.diagnosis.select.search` with ``moves``): a region 50 % stiffer over 40 x 39 mm of the
guided card (:func:`diagnosis_plates.guided_card`), measured at 72 points in ten modes, and the search
offered one candidate, the same rectangle three elements (40 mm) to its side, as a grid of patches may
place it. Fitted there, it predicts too few held-out modes and is refused; walked, it lands on the
region's cells with its change."""

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.moves import LocalMoves, rectangle
from pcbdyn.diagnosis.region_stiffness import KIND
from pcbdyn.diagnosis.residual import ModalResidual, Observation, reading
from pcbdyn.diagnosis.select import search
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata.data import Dofs, Points
from pcbdyn.testdata.simulate import simulate_on_model

from diagnosis_plates import guided_card

N_MODES = 10
DX, DY = 0.16 / 12, 0.18 / 14  # the card's element sizes
TRUTH = (5 * DX, 7 * DY, 8 * DX, 10 * DY)


def test_a_region_beside_the_only_candidate_is_walked_onto_and_found():
    m = guided_card()
    layout = dg.from_model(m)
    truth = dg.add_effect(m, KIND.rectangle(layout, *TRUTH), 0.5)
    xy = np.stack(np.meshgrid(np.linspace(0.01, 0.15, 8), np.linspace(0.01, 0.17, 9)), -1).reshape(-1, 2)
    ids = np.arange(1, len(xy) + 1)
    points, dofs = Points(ids, np.c_[xy, np.zeros(len(xy))]), Dofs(ids, np.tile([0.0, 0.0, 1.0], (len(ids), 1)))
    test = simulate_on_model(truth, solve_modes(truth, n_modes=N_MODES), points, dofs).modes
    ob = Observation(None, test, np.full(N_MODES, 0.002), read=reading(m, test.xyz, test.directions),
                     sigma_s=np.full(N_MODES, 0.02))
    res = ModalResidual([ob], lambda p: [m])
    beside = (TRUTH[0] + 3 * DX, TRUTH[1], TRUTH[2] + 3 * DX, TRUTH[3])
    found = {}
    for walk in (False, True):
        cands: list = []
        moves = LocalMoves(layout, cands, DX)
        moves.region("region_stiffness", beside)
        sel = search(res, cands, max_effects=1, moves=moves if walk else None)
        found[walk] = [(rectangle(cands[i]), v) for i, v in zip(sel.chosen, sel.values)]
    assert found[False] == []
    (box, change), = found[True]
    assert np.abs(np.subtract(box, TRUTH)).max() < 0.5 * DX and change == pytest.approx(0.5, rel=0.02)
