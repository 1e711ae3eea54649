"""Fixtures: the thesis' 10-DOF string (Table 5.5) and 18-element cantilever (Table 5.3)."""

import numpy as np
import pytest

from structures import beam_model, chain_model, load_case


@pytest.fixture
def string10():
    c = load_case("T5.5_string_10dof")["inputs"]
    p_a = np.concatenate([c["m_pa_kg"], np.array(c["k_pa_MN_per_m"]) * 1e6])
    p_x = np.concatenate([c["m_px_kg"], np.array(c["k_px_MN_per_m"]) * 1e6])
    return chain_model(10), p_a, p_x


@pytest.fixture
def cantilever():
    c = load_case("T5.3_cantilever_beam")
    i = c["inputs"]
    n_el = i["n_elem"]
    model = beam_model(i["L_m"], i["b_m"], i["h_m"], i["rho"], n_el)
    p_a = np.full(n_el, i["E_uniform"])
    p_x = p_a.copy()
    p_x[4:8] = i["E_el5_8_exp"]
    return model, p_a, p_x, c
