"""End to end without a board: a plate model, a simulated test of a stiffer plate written to UFF, read
back and correlated with the original model."""

import numpy as np
import pytest

from pcbdyn.correlation import correlate
from pcbdyn.fe import Model, ShellProperty
from pcbdyn.fe.generate import rectangle, rectangle_edges
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import Dofs, Noise, Points, read_uff, write_uff
from pcbdyn.testdata.simulate import simulate_on_model

A, B = 0.162, 0.178


def plate(E):
    nodes, cells = rectangle(A, B, 12, 12)
    m = Model(nodes)
    m.add("board", "quad4", cells, ShellProperty(E=E, nu=0.3, rho=2000.0, t=1.6e-3))
    m.fix(np.unique(np.concatenate(list(rectangle_edges(nodes, A, B).values()))), ["ux", "uy", "uz"])
    return m


def test_correlating_a_simulated_test_of_a_stiffer_plate_gives_the_expected_pair_table(tmp_path):
    model = plate(26e9)
    stiff = plate(26e9 * 1.02**2)  # every frequency 2 % higher, same shapes
    modes, stiff_modes = solve_modes(model, 6), solve_modes(stiff, 6)
    rng = np.random.default_rng(0)
    xy = np.column_stack([rng.uniform(0.01, A - 0.01, 40), rng.uniform(0.01, B - 0.01, 40), np.zeros(40)])
    pts = Points(np.arange(1, 41), xy)  # a vibrometer grid that ignores the mesh
    test = simulate_on_model(stiff, stiff_modes, pts, Dofs.from_codes(pts.ids, 3), excite=(0.135, 0.0636),
                             f_axis=np.arange(0.0, 1500.0, 0.5), zeta=0.01, noise=Noise(0.0, 2.0, 1.0), seed=1)
    assert test.points.ids[-1] == 41 and test.frfs.reference.point_ids.tolist() == [41]
    write_uff(tmp_path / "test.uff", test)
    back = read_uff(tmp_path / "test.uff")
    c = correlate(back.modes, model, modes, min_mac=0.8)
    d = c.to_dict()
    assert [p["test_mode"] for p in d["pairs"]] == [p["model_mode"] for p in d["pairs"]] == [1, 2, 3, 4, 5, 6]
    for p in d["pairs"]:
        assert p["df_pct"] == pytest.approx(100 * (1 / 1.02 - 1), abs=1e-3)
        assert p["mac"] > 0.99
    assert d["unpaired_test_modes"] == []
    assert len(d["comac"]) == 40 and min(d["comac"].values()) > 0.95
    assert "1:+z" in d["comac"]
