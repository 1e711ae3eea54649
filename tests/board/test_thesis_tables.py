"""The thesis' own FE tables, reproduced from board.toml descriptions (tests/data/reference/README.md
gives the assumptions: nu, spring units, locked edges, part layout)."""

import numpy as np
import pytest
from board_helpers import DATA, EXAMPLES, rel_err, thesis_case, write_board

from pcbdyn.board import build_model, load_board
from pcbdyn.fe.modal import solve_modes

WEDGE_LOCKS = '''
[[fixtures]]
name = "bottom"
type = "wedge_lock"
edge = "y=0"
k_rot = "{k}"

[[fixtures]]
name = "top"
type = "wedge_lock"
edge = "y=178 mm"
k_rot = "{k}"
'''


def frequencies(path, n, config=None):
    bm = build_model(load_board(path), config)
    return solve_modes(bm.model, n_modes=n).frequencies


def simulated_pcb(tmp_path, variant, k=None):
    """Table 5.11: 'pa' is the FE model (four parts 3.0 mm, two 3.2 mm), 'px' the simulated test
    (all six 3.2 mm)."""
    text = (DATA / "simulated_pcb.toml").read_text()
    if variant == "px":
        text = text.replace('thickness = "3.0 mm"', 'thickness = "3.2 mm"')
    if k is not None:
        text += WEDGE_LOCKS.format(k=k)
    return write_board(tmp_path, text)


@pytest.mark.parametrize("variant, column", [("pa", "free_FE_model(pa)"), ("px", "free_Experimental(px)")])
def test_table_5_11_free(tmp_path, variant, column):
    ref = thesis_case("T5.11_simulated_pcb")["thesis"][column]
    f = frequencies(simulated_pcb(tmp_path, variant), len(ref))
    err = rel_err(f, ref)
    assert np.max(np.abs(err)) < 0.04, np.round(100 * err, 2)


@pytest.mark.parametrize("variant, k, column", [("pa", "430 N*m/rad/m", "fixed_FE_model(pa)"),
                                                ("px", "500 N*m/rad/m", "fixed_Experimental(px)")])
def test_table_5_11_wedge_locked(tmp_path, variant, k, column):
    ref = thesis_case("T5.11_simulated_pcb")["thesis"][column]
    f = frequencies(simulated_pcb(tmp_path, variant, k), len(ref))
    err = rel_err(f, ref)
    assert abs(err[0]) < 0.01, np.round(100 * err, 2)
    assert np.max(np.abs(err)) < 0.04, np.round(100 * err, 2)


def test_table_7_4_configuration_1():
    ref = thesis_case("T7.4_real_pcb_free")["thesis"]["fa#1"]
    f = frequencies(EXAMPLES / "six_part_card" / "board.toml", len(ref))
    err = rel_err(f, ref)
    assert np.max(np.abs(err)) < 0.04, np.round(100 * err, 2)


@pytest.mark.parametrize("config, column", [("c2", "fa#2"), ("c3", "fa#3")])
def test_table_7_4_perturbed_configurations_first_three_modes(config, column):
    ref = thesis_case("T7.4_real_pcb_free")["thesis"][column][:3]
    f = frequencies(EXAMPLES / "six_part_card" / "board.toml", 3, config)
    err = rel_err(f, ref)
    assert np.max(np.abs(err)) < 0.05, np.round(100 * err, 2)


@pytest.mark.parametrize("k, column", [("hinged", "hinged (paired order)"), ("clamped", "clamped"),
                                       ("1e4 N*m/rad/m", "k=1e4"), ("30646 N*m/rad/m", "k=30646")])
def test_tables_7_12_to_7_15_card_in_wedge_locks(tmp_path, k, column):
    text = (EXAMPLES / "wedge_locked" / "board.toml").read_text()
    text = text.replace('k_rot = "1e4 N*m/rad/m"', f'k_rot = "{k}"')
    if k in ("hinged", "clamped"):  # no stiffness left to be a parameter
        text = text.split("[[parameters]]")[0] + "[analysis]\nmodes = 5\n"
    ref = np.sort(thesis_case("T7.12-7.15_pcb_wedge_lock")["thesis"][column])  # hinged: pair by order of frequency
    f = frequencies(write_board(tmp_path, text), len(ref))
    err = rel_err(f, ref)
    assert np.max(np.abs(err)) < 0.04, np.round(100 * err, 2)


def test_updated_wedge_lock_stiffness_through_the_parameter():
    """Table 7.15 again, setting the shared k_guides parameter on the 1e4 model."""
    bm = build_model(load_board(EXAMPLES / "wedge_locked" / "board.toml"))
    bm2 = bm.with_parameters({"k_guides": 30646.0})
    f = solve_modes(bm2.model, n_modes=5).frequencies
    err = rel_err(f, thesis_case("T7.12-7.15_pcb_wedge_lock")["thesis"]["k=30646"])
    assert np.max(np.abs(err)) < 0.04
    f0 = solve_modes(bm.model, n_modes=5).frequencies
    assert np.all(f > f0)  # a stiffer guide raises every mode
