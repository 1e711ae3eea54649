"""The plate theory's part of the model form (:mod:`pcbdyn.diagnosis.model_form`): the Kirchhoff
limit raises every frequency, more so on a mesh that resolves the shear at free edges, and its
share in a test's frequencies is recovered with the declared parameters."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pcbdyn.board import load_board
from pcbdyn.diagnosis import finer
from pcbdyn.diagnosis.model_form import fit_plate_share, kirchhoff_shift
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.diagnosis.scan import Runner
from pcbdyn.diagnosis.selection import Selection
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import model_probe
from pcbdyn.problems import StructureModels

from diagnosis_plates import measured
from test_discretisation import grid

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card" / "board.toml"
N_MODES = 7


def kirchhoff(board, models, h, ob, cs):
    """The Kirchhoff limit's relative change per paired mode of the card meshed at ``h``."""
    p, n = dict(zip(models.names, models.p0.tolist())), int(cs.pairs.max()) + finer.SPARE_MODES
    fine, limit = finer.solve(Runner(), board, p, [(None, h, k, (), n, (ob.modes.xyz, ob.modes.directions))
                                                   for k in (False, True)])
    return kirchhoff_shift(fine, limit, ob, cs)


def observed(board, models, theta, shifts=None):
    """An observation of the card's own modes at the points, frequencies moved by ``theta`` of the
    Kirchhoff ``shifts`` (0.05 % frequency and 1 % shape sigmas), its residual and the Kirchhoff shifts."""
    xyz, dirs = grid()
    bm = models.models[0]
    modes = solve_modes(bm.model, n_modes=N_MODES)
    P = model_probe(bm.model, xyz, dirs, tol=0.02).P
    ob = Observation(None, measured(modes.frequencies, np.asarray(P @ modes.shapes), xyz, dirs),
                     np.full(N_MODES, 5e-4), P, np.full(N_MODES, 0.01))
    res = ModalResidual.of_models(models, [ob])
    st = res.evaluate(models.p0)
    if shifts is None:
        shifts = [kirchhoff(board, models, board.mesh_size, ob, st.configs[0])]
    return res.on([replace(ob, modes=replace(ob.modes, frequencies=ob.f * (1.0 + theta * shifts[0])))]), shifts


@pytest.fixture(scope="module")
def card():
    board = load_board(CARD)
    return board, StructureModels(board, [None], shared_mesh=True)


def test_kirchhoff_limit_raises_every_mode_and_more_on_a_finer_mesh(card):
    """A rigid transverse shear is a constraint: no frequency falls (Rayleigh). The free-edge
    shear boundary layer, narrower than an element of the model's mesh, is what a finer mesh
    resolves: the largest gap grows with refinement (the reason it is measured on the finest mesh)."""
    board, models = card
    res, (coarse,) = observed(board, models, 0.0)
    fine = kirchhoff(board, models, board.mesh_size / 2.0, res.observations[0], res.evaluate(models.p0).configs[0])
    assert np.all(coarse > 0.0) and np.all(fine > 0.0)
    assert fine.max() > 1.2 * coarse.max()


@pytest.mark.parametrize("theta", [0.0, 0.6])
def test_plate_share_is_recovered_with_the_declared_parameters(card, theta):
    """Frequencies of the card's own model moved by a share theta of their Kirchhoff gap: the
    share comes back (0 where there is none: kept only when significant), the declared parameters
    stay where the data were made, the frequencies then match."""
    board, models = card
    res, shifts = observed(board, models, theta)
    st = res.evaluate(models.p0)
    sel = Selection(p=models.p0.copy(), chi2=[st.chi2], state=st)
    sel, got, sigma, res = fit_plate_share(res, [], sel, shifts, [o.sigma_f for o in res.observations], models.bounds)
    assert got == pytest.approx(theta, abs=0.05)
    assert np.allclose(sel.p, models.p0, rtol=0.02)
    ob, cs = res.observations[0], sel.state.configs[0]
    assert np.max(np.abs(cs.f_a / ob.f - 1.0)) < 2e-4
