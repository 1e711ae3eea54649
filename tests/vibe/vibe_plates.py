"""Simply supported plates for the vibration tests (board.toml text, Navier's frequencies, models)."""

import numpy as np

A, B, T = 0.16, 0.10, 1.6e-3  # [m]
E, NU, RHO = 22e9, 0.15, 1850.0
#: a 6 x 6 mm part of negligible mass whose library entry gives a Steinberg constant
TINY = ('[package]\nname = "TINY"\nsize = ["6 mm", "6 mm"]\nheight = "1 mm"\nmass = "0.01 g"\n'
        'default_model = "spread"\nequivalent_thickness = "1.6 mm"\nsteinberg_c = 1.0\n'
        'provenance = "test part: Steinberg constant of a standard DIP"\n')


def plate_toml(mesh_mm: float, parts=(), extra: str = "") -> str:
    """A simply supported A x B plate with TINY parts at ``parts`` [(ref, x_mm, y_mm)]."""
    edges = "".join(f'[[fixtures]]\ntype = "hinged_edge"\nedge = "{e}"\n'
                    for e in ("x=0", f"x={A * 1e3:g} mm", "y=0", f"y={B * 1e3:g} mm"))
    comps = "".join(f'[[components]]\nref = "{r}"\npackage = "TINY"\nat = ["{x:g} mm", "{y:g} mm"]\n'
                    for r, x, y in parts)
    return (f'[board]\nname = "simply supported plate"\noutline = {{ width = "{A * 1e3:g} mm", '
            f'height = "{B * 1e3:g} mm" }}\nthickness = "{T * 1e3:g} mm"\n'
            f'material = {{ E = "{E / 1e9:g} GPa", nu = {NU}, rho = "{RHO:g} kg/m^3" }}\n'
            f'mesh_size = "{mesh_mm:g} mm"\n{edges}{comps}{extra}[analysis]\nmodes = 12\n')


def write_plate(folder, mesh_mm: float, parts=(), extra: str = ""):
    """board.toml (and library/TINY.toml beside it) in ``folder``; returns the board path."""
    (folder / "library").mkdir(exist_ok=True)
    (folder / "library" / "TINY.toml").write_text(TINY)
    path = folder / "board.toml"
    path.write_text(plate_toml(mesh_mm, parts, extra))
    return path


def write_free_plate(folder):
    """free.toml: the plate with no fixture at all (a free board, which base excitation refuses)."""
    path = folder / "free.toml"
    path.write_text(f'[board]\nname = "free"\noutline = {{ width = "{A * 1e3:g} mm", height = "{B * 1e3:g} mm" }}\n'
                    f'thickness = "{T * 1e3:g} mm"\nmaterial = {{ E = "{E / 1e9:g} GPa", nu = {NU}, '
                    f'rho = "{RHO:g} kg/m^3" }}\nmesh_size = "20 mm"\n[analysis]\nmodes = 3\n')
    return path


def navier(m: int, n: int) -> float:
    """Kirchhoff frequency [Hz] of the (m, n) mode of the simply supported plate."""
    D = E * T**3 / (12 * (1 - NU**2))
    return 0.5 * np.pi * ((m / A) ** 2 + (n / B) ** 2) * np.sqrt(D / (RHO * T))


def solve(path, f_max: float):
    """(board, board model, modes up to f_max, K, M)."""
    from pcbdyn.board import build_model, load_board
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import solve_modes

    board = load_board(path)
    bm = build_model(board)
    K, M = assemble(bm.model)
    return board, bm, solve_modes(bm.model, n_modes=100, f_max=f_max, K=K, M=M), K, M
