"""Time per updating iteration on boards: sensitivities (dK/dp, dM/dp on the constrained DOFs),
equations (modal solve + pairing + frequency equations) and the solve, against one modal solve.

Cases: the six-part card (six thicknesses, three configurations' worth of one) and a ~20k-DOF
board with 20 parameters (20 parts' thicknesses). Then a whole update to convergence (issue 23): the
six-part card's four parameters against simulated tests of its three configurations (PGAs 30 % and
CQFPs 17 % thicker, truth meshed twice as fine, 0.2 % / 2 % noise), QMS, wall and CPU time with the
machine's load beside them (target <= 20 s). Run: python benchmarks/bench_update.py
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from pcbdyn.board import load_board  # noqa: E402
from pcbdyn.fe.modal import solve_modes  # noqa: E402
from pcbdyn.updating import build_equations, solve_bounded  # noqa: E402
from pcbdyn.problems import UpdateProblem  # noqa: E402
from pcbdyn.testdata import MeasuredModes  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def big_board(path: Path) -> Path:
    """A 240 x 200 mm board with 20 parts (4 x 5 grid), one thickness parameter each."""
    parts, params = [], []
    for i in range(20):
        x, y = 30 + 45 * (i % 5), 30 + 45 * (i // 5)
        parts.append(f'[[components]]\nref = "U{i + 1}"\npackage = "JLCC"\nat = ["{x} mm", "{y} mm"]\n')
        params.append(f'[[parameters]]\nname = "t_U{i + 1}"\ntarget = "components.U{i + 1}.thickness"\n'
                      'bounds = ["1 mm", "10 mm"]\n')
    path.write_text('[board]\noutline = { width = "240 mm", height = "200 mm" }\nthickness = "1.6 mm"\n'
                    'material = { E = "24 GPa", nu = 0.3, rho = "1900 kg/m^3" }\nmesh_size = "5 mm"\n\n'
                    + "\n".join(parts) + "\n" + "\n".join(params))
    return path


def bench(name, board, n_modes, points=None):
    prob = UpdateProblem(board)
    sysm = prob.system(None)
    t = time.perf_counter()
    modes = solve_modes(sysm.pm.model, n_modes=n_modes)
    t_modal = time.perf_counter() - t
    p = prob.p0 * 1.0001
    bm = sysm.at(p)
    t = time.perf_counter()
    for par in prob.names:
        dK, dM = bm.parameters[par].derivatives(bm)
        sysm.reduction.reduce(dK), sysm.reduction.reduce(dM)
    t_deriv = time.perf_counter() - t
    t = time.perf_counter()
    K, M, dKs, dMs = sysm.model(p)
    t_sens = time.perf_counter() - t
    cfg = prob.configuration(None, MeasuredModes.frequencies_only(modes.frequencies * 1.01), "freq")
    t = time.perf_counter()
    (A, b), _, _ = build_equations([cfg], p)  # model(p) cached: modes + equations
    t_eq = time.perf_counter() - t
    t = time.perf_counter()
    solve_bounded(A, b, np.log(prob.bounds[0] / p), prob.bounds[1] / p - 1)
    t_solve = time.perf_counter() - t
    print(f"{name}: {K.shape[0]} constrained DOFs, {len(prob.names)} parameters, {n_modes} modes")
    print(f"  one modal solve (fe.modal, CHOLMOD)       {t_modal:7.2f} s")
    print(f"  {len(dKs)} x (dK/dp, dM/dp), reduced              {t_deriv:7.2f} s")
    print(f"  model(p): assembly + derivatives          {t_sens:7.2f} s")
    print(f"  equations (driver's modal solve + eq 3.6) {t_eq:7.2f} s")
    print(f"  bounded LS solve                          {t_solve:7.3f} s")
    print(f"  iteration total                           {t_sens + t_eq + t_solve:7.2f} s")
    if points is not None:
        from pcbdyn.fe.probe import model_probe
        from pcbdyn.testdata.csvio import read_points_csv

        pts, dofs = read_points_csv(points)
        xyz = pts.xyz[pts.index(dofs.point_ids)]
        shapes = np.asarray(model_probe(sysm.pm.model, xyz, dofs.directions).P @ modes.shapes)
        meas = MeasuredModes(pts, dofs, modes.frequencies * 1.01, shapes)
        qms = prob.mode_configurations(None, meas, "qms")
        t = time.perf_counter()
        build_equations(qms, p)
        print(f"  QMS equations, {len(qms)} modes at {len(xyz)} points (dynamic condensation per mode) "
              f"{time.perf_counter() - t:5.2f} s")


def qms_card() -> None:
    """The six-part card's QMS update over three configurations, to convergence."""
    from pcbdyn.problems import run
    from pcbdyn.testdata import Noise, read_points_csv
    from pcbdyn.testdata.simulate import simulate_on_model

    card = load_board(ROOT / "examples/six_part_card/board.toml")
    pts, dofs = read_points_csv(ROOT / "examples/six_part_card/points.csv")
    tests = []
    for k, c in enumerate([None, "c2", "c3"]):
        pm = card.build(c, mesh_size=card.mesh_size / 2).with_parameters({"t_PGA": 4.55e-3, "t_CQFP": 4.095e-3})
        td = simulate_on_model(pm.model, solve_modes(pm.model, n_modes=7), pts, dofs,
                               noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=k)
        tests.append((c, td.modes))
    load, wall, cpu = os.getloadavg()[0], time.perf_counter(), time.process_time()
    prob = UpdateProblem(card)
    check = [prob.configuration(c, m, "freq") for c, m in tests]
    cfgs = [q for c, m in tests for q in prob.mode_configurations(c, m, "qms")]
    res, before, after = run(prob, cfgs, "bounded", check=check, max_iter=20, tol_freq_pct=0.1)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f"\nsix-part card, QMS, 3 configurations ({len(cfgs)} mode blocks), {len(prob.names)} parameters: "
          f"{res.iterations} iterations, {res.reason}")
    print("  " + ", ".join(f"{n} {v:.6g}" for n, v in prob.values(res.p).items()))
    print(f"  max |df| {max(s['max_freq_error_pct'] for s in before):.2f} % -> "
          f"{max(s['max_freq_error_pct'] for s in after):.2f} %")
    print(f"  to convergence: {wall:.1f} s wall, {cpu:.1f} s CPU (load {load:.1f}; target <= 20 s)")


if __name__ == "__main__":
    import re

    with tempfile.TemporaryDirectory() as d:
        text = (ROOT / "examples/six_part_card/board.toml").read_text().split("[[parameters]]")[0]
        text += "".join(f'\n[[parameters]]\nname = "t_U{i}"\ntarget = "components.U{i}.thickness"\n'
                        'bounds = ["2 mm", "10 mm"]\n' for i in range(1, 7))
        p = Path(d) / "card.toml"
        p.write_text(re.sub(r"\n#.*", "", text))
        bench("six-part card", load_board(p), 7, ROOT / "examples/six_part_card/points.csv")
        bench("20-part board", load_board(big_board(Path(d) / "big.toml")), 10)
    qms_card()
