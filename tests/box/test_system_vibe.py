"""vibe on a system: the base excitation at the housing's supports, every card's parts judged on the card's
own model from the system's modal response, against a direct frequency response of the full system."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from system_helpers import ALUMINIUM, housing

from pcbdyn.box import load_box
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import reduced_system, solve_modes
from pcbdyn.fe.probe import model_probe
from pcbdyn.vibration import G, Psd, parse_damping
from pcbdyn.vibration.base_excitation import influence_vector
from pcbdyn.vibration.spectra import trapezoid_weights
from pcbdyn.vibration.system import assess_system

BETA = 2e-5  # [s] stiffness-proportional damping C = beta K: modal zeta_r = beta omega_r / 2


def _direct_psd(system, K, M, card, refs, grid, psd, axis="z"):
    """PSD [m^2/Hz] of the displacement normal to the card at its parts' centres, relative to the supports,
    by solving ((1 + i omega beta) K - omega^2 M) u = -M r at every frequency of ``grid`` on the full
    system (SuperLU, column ordering of A^T A: the symmetric ordering fills this pencil in ten times more)."""
    pc = system.cards[card]
    at = np.array([pc.card.board.component(r).at for r in refs])
    sets = [n for n in system.model.sets if n.startswith(f"cards.{card}.")]
    P = model_probe(system.model, pc.card.point(at), pc.card.normal, sets=sets).P
    red, Kr, Mr = reduced_system(system.model, K, M)
    F = red.T.T @ (M @ influence_vector(M.shape[0], axis))
    out = []
    for f in grid:
        om = 2 * np.pi * f
        Z = sp.csc_matrix((1 + 1j * om * BETA) * Kr - om**2 * Mr)
        Z.indices, Z.indptr = Z.indices.astype(np.int32), Z.indptr.astype(np.int32)
        u = spla.splu(Z, permc_spec="MMD_ATA").solve(-F.astype(complex))
        out.append(np.abs(P @ red.expand(u)) ** 2 * psd.at(f))
    return np.array(out)


def test_card_parts_in_a_housing_match_a_direct_frequency_response(tmp_path):
    """The shelf in 2 mm aluminium walls under a flat 0.04 g^2/Hz from 20 to 400 Hz along z (its first
    three modes), stiffness-proportional damping: the modes up to twice the spectrum's top with the
    static residual against the direct solution, every part's RMS displacement within 2 %."""
    system = load_box(housing(tmp_path, 2.0, ALUMINIUM)).build(mesh_size=0.02)
    K, M = assemble(system.model)
    psd = Psd("flat", "test", np.array([20.0, 400.0]), np.full(2, 0.04 * G**2))
    modes = solve_modes(system.model, f_max=2 * psd.f[-1], K=K, M=M)
    zeta = BETA * np.pi * modes.frequencies
    a = assess_system(system, modes, K, M, psd, parse_damping("zeta=0.02"), zeta=zeta)
    card = a.cards["card1"]
    refs = [p.ref for p in card.parts]
    sub = np.arange(0, card.grid.size, 8)  # the same points for both: what is compared is the response
    w = trapezoid_weights(card.grid[sub])[:, None]
    direct = np.sqrt((w * _direct_psd(system, K, M, "card1", refs, card.grid[sub], psd)).sum(axis=0))
    ours = np.sqrt((w * card.part_z_psd[sub]).sum(axis=0))
    assert np.allclose(ours, direct, rtol=0.02), (ours, direct)
    full = np.array([p.z_rms_m for p in card.parts])
    assert np.allclose(ours, full, rtol=0.1)  # the subset still resolves the response
    assert card.octave is not None and card.octave["board_hz"] == pytest.approx(modes.frequencies[0])
