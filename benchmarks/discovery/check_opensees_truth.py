"""Checks of the OpenSees converter (:mod:`opensees_truth`): a plain script printing tables.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/discovery/check_opensees_truth.py [--timing] [--shell ASDShellQ4]

a. simply supported square plate against Kirchhoff's f_mn;
b. a beam alone (Iy != Iz, skew axis, offset) against pcbdyn's beam (axes and offset);
c. the example boards, a card with one entry of each kind and a card with only a stiffener,
   pcbdyn against OpenSees: frequencies, ratio and MAC (z DOFs) of the shapes paired by max MAC;
d. the ribbed housing of seed 0 (tall ribs: their rotary inertia) at the model's mesh;
--timing: solve_opensees on the six-part card at three mesh sizes; --shell: the shell element of c.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from opensees_truth import solve_opensees  # noqa: E402

from pcbdyn.board import build_model, load_board  # noqa: E402
from pcbdyn.fe.modal import solve_modes  # noqa: E402
from pcbdyn.fe.model import Model  # noqa: E402
from pcbdyn.fe.properties import BeamProperty, ShellProperty  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CARD = ROOT / "examples" / "six_part_card" / "board.toml"
WEDGE = ROOT / "examples" / "wedge_locked" / "board.toml"

EXTRA = """
[[masses]]
name = "relay"
at = ["140 mm", "150 mm"]
mass = "25 g"
inertia = "2e-6 kg*m^2"

[[fixtures]]
name = "standoff"
type = "point_spring"
at = ["81 mm", "113 mm"]
k = "1.5e5 N/m"

[[fixtures]]
name = "tight"
type = "edge_spring"
from = ["40.5 mm", "178 mm"]
to = ["121.5 mm", "178 mm"]
k_rot = "1e4 N*m/rad/m"

[[line_masses]]
name = "conn"
from = ["0 mm", "50 mm"]
to = ["0 mm", "100 mm"]
mass = "25 g"
"""
RIB = """
[[stiffeners]]
name = "rib"
path = [["0 mm", "112 mm"], ["162 mm", "112 mm"]]
EI = "1 N*m^2"
"""
REGION = """
[[regions]]
name = "spreader"
rect = ["118 mm", "93 mm", "158 mm", "133 mm"]
stiffness_factor = 4
"""


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return (a.T @ b) ** 2 / np.outer((a * a).sum(0), (b * b).sum(0))


def ss_plate(n: int = 40, a: float = 0.2, t: float = 2e-3, E: float = 70e9, nu: float = 0.3, rho: float = 2700.0):
    x = np.linspace(0.0, a, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    nodes = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    k = (i * (n + 1) + j).ravel()
    m = Model(nodes)
    m.add("plate", "quad4", np.column_stack([k, k + n + 1, k + n + 2, k + 1]), ShellProperty(E, nu, rho, t))
    on_edge = np.isclose(nodes[:, :2], 0.0).any(1) | np.isclose(nodes[:, :2], a).any(1)
    m.fix(np.flatnonzero(on_edge), ["uz"])
    m.fix([0], ["ux", "uy"])
    m.fix([n * (n + 1)], ["uy"])  # the corner (a, 0): no in-plane rigid motion
    D = E * t**3 / (12.0 * (1.0 - nu**2))
    exact = sorted(np.pi / 2 * ((p / a) ** 2 + (q / a) ** 2) * np.sqrt(D / (rho * t))
                   for p in range(1, 4) for q in range(1, 4))
    return m, np.array(exact[:4])


def check_plate() -> None:
    m, exact = ss_plate()
    print("a. simply supported plate 0.2 x 0.2 x 0.002 m, 40 x 40 quads: f [Hz] (ratio to Kirchhoff)")
    print(f"  {'Kirchhoff':>10s}" + "".join(f"{f:10.2f}        " for f in exact))
    for shell in ("ShellDKGQ", "ShellMITC4", "ASDShellQ4"):
        f, _ = solve_opensees(m, 4, shell)
        print(f"  {shell:>10s}" + "".join(f"{a:10.2f} ({a / b:.4f})" for a, b in zip(f, exact)))


def check_beam() -> None:
    L, n = 0.5, 20
    d = np.array([0.3, 0.2, 0.1]) / np.linalg.norm([0.3, 0.2, 0.1])
    m = Model(np.outer(np.linspace(0.0, L, n + 1), d))
    p = BeamProperty(E=70e9, nu=0.3, rho=2700.0, A=1e-4, Iy=2e-9, Iz=2e-10, J=5e-10, orientation=(0.0, 0.3, 1.0),
                     offset=(0.01, -0.02, 0.015), rotary_inertia=False)
    m.add("beam", "beam2", np.column_stack([np.arange(n), np.arange(1, n + 1)]), p)
    m.fix([0])
    ours = solve_modes(m, n_modes=6)
    f, s = solve_opensees(m, 6)
    mm = mac(ours.shapes.reshape(n + 1, 6, -1)[:, :3].reshape(-1, 6), s[:, :3].reshape(-1, 6))
    print("\nb. skew cantilever beam, Iy = 10 Iz, offset (10, -20, 15) mm (translations for the MAC)")
    table(ours.frequencies, f, mm)


def table(fo, f, mm, n=None) -> None:
    n = n or len(fo)
    j = mm.argmax(1)
    print(f"  {'mode':>4s} {'pcbdyn':>9s} {'OpenSees':>9s} {'ratio':>7s} {'MAC':>7s}")
    for i in range(n):
        print(f"  {i + 1:4d} {fo[i]:9.2f} {f[j[i]]:9.2f} {f[j[i]] / fo[i]:7.4f} {mm[i, j[i]]:7.4f}")


def compare(label: str, toml_text: str, h: float, n: int = 8, shell: str = "ShellDKGQ") -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "board.toml"
        path.write_text(toml_text)
        m = build_model(load_board(path), None, h, shared_mesh=True).model
    ours = solve_modes(m, n_modes=n)
    t0 = time.perf_counter()
    f, s = solve_opensees(m, n + 2, shell)
    dt = time.perf_counter() - t0
    print(f"\n{label}, mesh {h * 1e3:g} mm, {m.n_nodes} nodes, {shell} ({dt:.1f} s)")
    table(ours.frequencies, f, mac(ours.shapes[2::6], s[:, 2, :]), n)


def check_housing(seed: int = 0) -> None:
    """The ribbed housing of ``seed`` (:mod:`housings`, its true values and effects) at the model's mesh:
    the ribs' rotary inertia, lumped on OpenSees' axis nodes, against pcbdyn's consistent one."""
    from housings import _model, draw

    h = draw(seed)
    m = _model(h, True, h.mesh_mm)
    ours = solve_modes(m, n_modes=h.test_modes)
    f, s = solve_opensees(m, h.test_modes + 2, h.shell)
    print(f"\nd. housing h{seed:04d}, mesh {h.mesh_mm:g} mm, {m.n_nodes} nodes, {h.shell} (translations for the MAC)")
    table(ours.frequencies, f, mac(ours.shapes.reshape(m.n_nodes, 6, -1)[:, :3].reshape(-1, ours.frequencies.size),
                                   s[:, :3].reshape(-1, f.size)))


def timing() -> None:
    print("\ntiming of solve_opensees(model, 10) on the six-part card")
    for h in (6.75e-3, 3.375e-3, 1.6875e-3):
        m = build_model(load_board(CARD), None, h, shared_mesh=True).model
        t0 = time.perf_counter()
        solve_opensees(m, 10)
        print(f"  {h * 1e3:7.4f} mm {m.n_nodes:6d} nodes {6 * m.n_nodes:6d} DOF {time.perf_counter() - t0:6.1f} s")


if __name__ == "__main__":
    card, wedge = CARD.read_text(), WEDGE.read_text()
    shell = sys.argv[sys.argv.index("--shell") + 1] if "--shell" in sys.argv else "ShellDKGQ"
    check_plate()
    check_beam()
    compare("c. six-part card (free)", card, 3.375e-3, shell=shell)
    compare("c. wedge-locked card", wedge, 3.375e-3, shell=shell)
    compare("c. card + mass, springs, edge spring, line mass, rib, region", card + EXTRA + RIB + REGION, 3.375e-3,
            shell=shell)
    for h in (3.375e-3, 1.6875e-3):
        compare("c. card + rib only", card + RIB, h, shell=shell)
    check_housing()
    if "--timing" in sys.argv:
        timing()
