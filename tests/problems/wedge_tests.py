"""Simulated tests of the six-part card in its wedge-lock guides (examples/wedge_locked): the card with
given guide stiffnesses, meshed twice as fine as the model, read at the example's grid with the thesis'
noise (2 % shapes, 0.2 % frequencies, eqs. 5.72-5.73)."""

from functools import lru_cache
from pathlib import Path

from pcbdyn.board import load_board
from pcbdyn.fe.modal import solve_modes
from pcbdyn.problems import guides
from pcbdyn.testdata import Noise, read_points_csv
from pcbdyn.testdata.simulate import simulate_on_model

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "wedge_locked"
BOARD = EXAMPLE / "board.toml"
NOISE = Noise(frequency_pct=0.2, shape_pct=2.0)
N_MODES = 5


@lru_cache(maxsize=8)
def simulated_test(k_bottom, k_top, n_modes: int = N_MODES, seed: int = 1):
    """The test (:class:`pcbdyn.testdata.TestData`: points and modes) of the card with guide stiffnesses
    k_bottom, k_top [N*m/rad/m] (or "clamped"/"hinged"), its first ``n_modes`` modes, meshed at half the
    card's mesh size. Cached: copy before changing it."""
    board = load_board(BOARD)
    truth = guides.with_guides(board, {"bottom_guide": k_bottom, "top_guide": k_top})
    pm = truth.build(None, board.mesh_size / 2.0)
    modes = solve_modes(pm.model, n_modes=n_modes)
    points, dofs = read_points_csv(EXAMPLE / "points.csv")
    return simulate_on_model(pm.model, modes, points, dofs, noise=NOISE, seed=seed)
