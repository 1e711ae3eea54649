"""``pcbdyn pretest`` (issue 41) on the six-part card: sensors by Effective Independence with the AutoMAC
guard, their mass loading, the exciter, and the suspension of the free card checked on the card built
with the springs as ``point_spring`` fixtures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pcbdyn.board import load_board
from pcbdyn.correlation.mac import automac
from pcbdyn.fe.modal import solve_modes
from pcbdyn.problems.pretest import (choose_exciter, choose_sensors, choose_suspension, mass_loading, pretest_model,
                                     sensor_directions)
from pcbdyn.problems.pretest_points import candidate_grid, read_candidates

CARD = Path(__file__).resolve().parents[2] / "examples/six_part_card"


@pytest.fixture(scope="module")
def card():
    board = load_board(CARD / "board.toml")
    return board, pretest_model(board, [], n_modes=7), read_candidates(board, CARD / "points.csv")


def greedy_efi_log_det(Phi, n_keep):
    """Textbook greedy EfI by brute force: drop, one at a time, the row whose removal leaves the largest
    det(Phi^T Phi)."""
    keep = list(range(Phi.shape[0]))
    while len(keep) > n_keep:
        lds = [np.linalg.slogdet(Phi[[k for k in keep if k != i]].T @ Phi[[k for k in keep if k != i]])[1]
               for i in keep]
        keep.pop(int(np.argmax(lds)))
    return np.linalg.slogdet(Phi[keep].T @ Phi[keep])[1], keep


def test_sensors_on_the_81_grid_points(card):
    """12 sensors for 7 modes among the 81 grid points: log det(Phi^T Phi) within 0.5 of greedy EfI and
    the largest off-diagonal AutoMAC <= 0.25 (greedy EfI alone exceeds it here)."""
    board, model, cand = card
    assert len(cand) == 81
    dirs, _, _ = sensor_directions(cand, False)
    Phi = np.asarray(model.read(cand.xyz, dirs) @ model.phi)
    ref, keep = greedy_efi_log_det(Phi, 12)
    s = choose_sensors(model, cand, 12, triaxial=False, max_automac=0.25)
    assert s.chosen.size == 12 and len(s.codes) == 12 and set(s.codes) == {"+z"}
    assert s.result.efi_log_det == pytest.approx(ref, abs=1e-9)  # the EfI start is the greedy set
    chosen_ld = np.linalg.slogdet(Phi[s.chosen].T @ Phi[s.chosen])[1]
    assert chosen_ld == pytest.approx(s.result.log_det, abs=1e-9)
    assert chosen_ld >= ref - 0.5
    off = automac(Phi[s.chosen]) - np.eye(7)
    assert off.max() <= 0.25 + 1e-12 and off.max() == pytest.approx(s.result.automac_max, abs=1e-12)
    assert (automac(Phi[keep]) - np.eye(7)).max() > 0.25  # the guard had something to do
    # and a random dozen of the candidates sees the modes far worse
    rng = np.random.default_rng(0)
    rand = [np.linalg.slogdet(Phi[r].T @ Phi[r])[1] for r in (rng.choice(81, 12, replace=False) for _ in range(200))]
    assert chosen_ld > np.percentile(rand, 99)


def test_sensor_mass_loading_against_the_card_with_the_masses_built_in(card, tmp_path):
    """The frequency shifts that sensors make: for 0.2 g ones the first order (Rayleigh quotient) is close
    to the re-solve; 2 g ones (12 of them: 24 g on a card of about 300 g, -10 to -20 %) re-solved agree
    with the card built with the masses as [[masses]] entries (its own nodes there)."""
    board, model, cand = card
    s = choose_sensors(model, cand, 12, triaxial=False)
    light = mass_loading(model, cand.xyz[s.chosen], 0.0002)
    np.testing.assert_allclose(light["first_order_pct"], light["shift_pct"], rtol=0.1)
    loading = mass_loading(model, cand.xyz[s.chosen], 0.002)
    shift = loading["shift_pct"]
    assert np.all(shift < -5)
    text = (CARD / "board.toml").read_text()
    text += "".join(f'\n[[masses]]\nname = "s{k}"\nat = ["{x * 1e3:g} mm", "{y * 1e3:g} mm"]\nmass = "2 g"\n'
                    for k, (x, y, _) in enumerate(cand.xyz[s.chosen].tolist()))
    (tmp_path / "loaded.toml").write_text(text)
    loaded = load_board(tmp_path / "loaded.toml").build()
    f = solve_modes(loaded.model, n_modes=7).frequencies
    np.testing.assert_allclose(100 * (f / model.frequencies - 1), shift, atol=0.05 * np.abs(shift).max())


def test_exciter_drives_every_mode(card):
    """The exciter's smallest share over the 7 modes is the best any of the 81 points offers, and no
    target mode has a nodal line through it (share > 0.3)."""
    _, model, cand = card
    e = choose_exciter(model, cand)
    Phi = np.abs(np.asarray(model.read(cand.xyz, np.tile([0, 0, 1.0], (81, 1))) @ model.phi))
    shares = Phi / Phi.max(axis=0)
    assert shares[e["index"]].min() == pytest.approx(shares.min(axis=1).max())
    np.testing.assert_allclose(e["share"], shares[e["index"]])
    assert e["share"].min() > 0.3


def test_free_card_suspension_with_the_springs_added(card, tmp_path):
    """The free card hung on the chosen springs (point_spring fixtures of the chosen stiffness, built by
    the board's own builder): suspension modes below 15 % of the first elastic mode, no elastic mode
    shifted by more than 0.2 %."""
    board, model, _ = card
    grid = candidate_grid(board, 0.0135)
    assert not all(grid.usable) and all(grid.usable[[i for i, p in enumerate(grid.on_part) if not p]])
    sus = choose_suspension(model, grid, share=0.1)
    assert not any(grid.on_part[i] for i in sus.chosen)
    text = (CARD / "board.toml").read_text()
    text += "".join(f'\n[[fixtures]]\nname = "hang{k}"\ntype = "point_spring"\nat = ["{x * 1e3!r} mm", '
                    f'"{y * 1e3!r} mm"]\nk = "{float(sus.k)!r} N/m"\n' for k, (x, y, _) in enumerate(grid.xyz[sus.chosen].tolist()))
    (tmp_path / "hung.toml").write_text(text)
    hung = load_board(tmp_path / "hung.toml").build()
    f = solve_modes(hung.model, n_modes=10).frequencies
    f1 = model.frequencies[0]
    suspension, elastic = f[:3], f[3:10]
    assert suspension.max() < 0.15 * f1
    assert np.max(np.abs(elastic / model.frequencies - 1)) < 0.002
    np.testing.assert_allclose(np.sort(suspension), np.sort(sus.solved_hz[3:]), rtol=0.02)
