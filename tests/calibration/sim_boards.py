"""Simulated calibration data: boards of different layouts carrying PGA, CQFP and JLCC parts (the
shipped families, thesis Table 7.1), their truth (every part at its own equivalent thickness, the
family's true mean scattered part to part, meshed twice as fine) and modal tests simulated on that
truth with the thesis' noise (eqs. 5.72-5.73)."""

from __future__ import annotations

import numpy as np

from pcbdyn.board import load_board
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import Dofs, Points
from pcbdyn.testdata.noise import Noise
from pcbdyn.testdata.simulate import simulate_on_model
from pcbdyn.testdata.uff import write_uff

#: [mm] the true mean equivalent thickness of each family (the shipped library says 3.5 mm for all)
TRUE_MM = {"PGA": 4.6, "CQFP": 4.2, "JLCC": 2.8}
#: part-to-part scatter of the true thicknesses (standard deviation, relative)
SCATTER = 0.03
MESH_MM = 8.0
NOISE = Noise(frequency_pct=0.2, shape_pct=2.0)

#: name: (width, height [mm], [(family, x, y [mm])])
LAYOUTS = {
    "b1": (170, 130, [("PGA", 35, 35), ("CQFP", 85, 35), ("JLCC", 135, 35), ("JLCC", 35, 95), ("PGA", 85, 95),
                      ("CQFP", 135, 95)]),
    "b2": (140, 160, [("CQFP", 35, 30), ("PGA", 100, 35), ("JLCC", 30, 80), ("JLCC", 105, 85), ("PGA", 40, 128),
                      ("CQFP", 105, 130)]),
    "b3": (190, 110, [("JLCC", 25, 25), ("PGA", 75, 70), ("CQFP", 125, 28), ("PGA", 162, 78), ("CQFP", 28, 80),
                      ("JLCC", 125, 85)]),
    "b4": (150, 150, [("PGA", 40, 110), ("CQFP", 110, 110), ("JLCC", 35, 35), ("JLCC", 110, 40), ("CQFP", 75, 70)]),
}


def board_text(name: str, mesh_mm: float = MESH_MM, thickness_mm=None) -> str:
    """board.toml of layout ``name``; ``thickness_mm`` {ref: mm} gives parts their own thickness."""
    w, h, parts = LAYOUTS[name]
    text = (f'[board]\nname = "{name}"\noutline = {{ width = "{w} mm", height = "{h} mm" }}\nthickness = "2 mm"\n'
            f'material = {{ E = "24 GPa", nu = 0.3, rho = "2000 kg/m^3" }}\nmesh_size = "{mesh_mm} mm"\n')
    for i, (fam, x, y) in enumerate(parts):
        ref = f"U{i + 1}"
        text += f'\n[[components]]\nref = "{ref}"\npackage = "{fam}"\nat = ["{x} mm", "{y} mm"]\n'
        if thickness_mm is not None:
            text += f'thickness = "{thickness_mm[ref]} mm"\n'
    return text + "\n[analysis]\nmodes = 8\n"


def true_thicknesses(name: str, seed: int) -> dict:
    """{ref: mm}: each part at its family's true mean times (1 + SCATTER N(0, 1))."""
    rng = np.random.default_rng(seed)
    return {f"U{i + 1}": round(TRUE_MM[fam] * (1 + SCATTER * rng.standard_normal()), 4)
            for i, (fam, _, _) in enumerate(LAYOUTS[name][2])}


def grid(name: str, nx: int = 9, ny: int = 7):
    """(Points, Dofs): a grid of +z measurement points over the board."""
    w, h, _ = LAYOUTS[name]
    X, Y = np.meshgrid(np.linspace(0, w, nx), np.linspace(0, h, ny))
    xyz = np.c_[X.ravel(), Y.ravel(), np.zeros(X.size)] * 1e-3
    ids = np.arange(1, X.size + 1)
    return Points(ids, xyz), Dofs(ids, [0.0, 0.0, 1.0])


def write_case(tmp_path, name: str, seed: int, n_modes: int = 8):
    """(board.toml to calibrate, test.uff simulated on the truth, {ref: true mm}) in ``tmp_path``."""
    t = true_thicknesses(name, seed)
    truth = tmp_path / f"{name}_truth.toml"
    truth.write_text(board_text(name, MESH_MM / 2, t))
    model = load_board(truth).build().model
    pts, dofs = grid(name)
    td = simulate_on_model(model, solve_modes(model, n_modes=n_modes), pts, dofs, noise=NOISE, seed=seed)
    uff = tmp_path / f"{name}_test.uff"
    write_uff(uff, td)
    board = tmp_path / f"{name}.toml"
    board.write_text(board_text(name))
    return board, uff, t


def simulated_test(board_path, uff_path, name: str, n_modes: int = 6, seed: int = 0):
    """A test of ``board_path`` as it is (its own mesh, the thesis' noise) on the grid of layout ``name``."""
    model = load_board(board_path).build().model
    pts, dofs = grid(name)
    write_uff(uff_path, simulate_on_model(model, solve_modes(model, n_modes=n_modes), pts, dofs, noise=NOISE,
                                          seed=seed))
    return uff_path
