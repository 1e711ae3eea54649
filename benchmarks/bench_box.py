"""A ribbed box of about 50k DOF: meshing and building, 20 modes, and one updating iteration with six
parameters (sensitivities dK/dp, dM/dp, the modal solve with MAC pairing and the frequency equations, the
bounded solve, the model at the new parameters), with memory; and the thesis' workflow at full size (the
test structure with shell-strip ribs meshed twice as fine, upper plate E x 0.7 and rho x 1.3, 2 % shape and
0.2 % frequency noise at the 143 points x 3 directions of examples/ribbed_box/points.csv): the update's
iterations, errors and parameters. Run: python benchmarks/bench_box.py
"""

from __future__ import annotations

import os
import resource
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import tomlkit  # noqa: E402

from pcbdyn.box import load_box  # noqa: E402
from pcbdyn.fe.modal import solve_modes  # noqa: E402
from pcbdyn.problems import UpdateProblem, run  # noqa: E402
from pcbdyn.testdata import Noise, read_points_csv  # noqa: E402
from pcbdyn.testdata.simulate import simulate_on_model  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "ribbed_box" / "box.toml"
SIX = ["E_upper", "rho_upper", "h_side", "h_back", "h_upper_x", "t_left"]


def variant(folder: Path, name: str, mesh_mm: float, rib_model: str = "beam", truth: bool = False) -> Path:
    doc = tomlkit.parse(EXAMPLE.read_text())
    doc["box"]["mesh_size"] = f"{mesh_mm} mm"
    doc["box"]["rib_model"] = rib_model
    if truth:
        del doc["parameters"]
        doc["plates"][3]["E"], doc["plates"][3]["rho"] = "49 GPa", "3510 kg/m^3"
    else:
        p = tomlkit.table()
        p.update({"name": "t_left", "target": "plates.left.thickness", "bounds": ["1 mm", "4 mm"]})
        doc["parameters"].append(p)
    path = folder / name
    path.write_text(tomlkit.dumps(doc))
    return path


def rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def one_iteration(box, test, n_modes: int = 20):
    """Times of one bounded updating iteration on six parameters (frequency equations weighted by the noise)."""
    from pcbdyn.updating import build_equations, solve_bounded

    prob = UpdateProblem(box, SIX)
    cfg = prob.configuration(None, test, "freq", n_modes=n_modes,
                             sigma=0.002 / np.sqrt(3) * test.frequencies)
    sysm = prob.system(None)
    t = time.perf_counter()
    sysm.model(prob.p0)
    t_sens = time.perf_counter() - t
    t = time.perf_counter()
    (A, b), _, _ = build_equations([cfg], prob.p0)
    t_eq = time.perf_counter() - t
    t = time.perf_counter()
    lo, hi = prob.bounds
    sol = solve_bounded(A, b, lo / prob.p0 - 1, hi / prob.p0 - 1)
    t_solve = time.perf_counter() - t
    t = time.perf_counter()
    build_equations([cfg], prob.p0 * (1 + sol.x))
    t_next = time.perf_counter() - t
    return t_sens, t_eq, t_solve, t_next, A.shape


def main():
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        print("ribbed box of examples/ribbed_box at about 50k DOF")
        box = load_box(variant(tmp, "big.toml", 3.8))
        t = time.perf_counter()
        pm = box.build()
        t_build = time.perf_counter() - t
        t = time.perf_counter()
        modes = solve_modes(pm.model, n_modes=20)
        t_modal = time.perf_counter() - t
        print(f"  mesh 3.8 mm: {pm.model.n_dof} DOF, {len(pm.mesh.nodes)} shell nodes; build {t_build:.2f} s, "
              f"20 modes {t_modal:.2f} s ({modes.frequencies[0]:.1f}-{modes.frequencies[-1]:.1f} Hz); "
              f"peak RSS {rss_mb():.0f} MB")
        points, dofs = read_points_csv(EXAMPLE.with_name("points.csv"))
        test = simulate_on_model(pm.model, modes, points, dofs, tol=0.02).modes
        t_sens, t_eq, t_solve, t_next, shape = one_iteration(box, test.subset(np.arange(12)))
        print(f"  one update iteration, 6 parameters, 12 test modes ({shape[0]} x {shape[1]} equations): "
              f"sensitivities {t_sens:.2f} s, modes + pairing + equations {t_eq:.2f} s, bounded solve "
              f"{t_solve * 1e3:.1f} ms, next model {t_next:.2f} s; total {t_sens + t_eq + t_solve + t_next:.2f} s; "
              f"peak RSS {rss_mb():.0f} MB")
        print("\nthe thesis workflow at full size (model 5 mm, test structure 2.5 mm with shell-strip ribs)")
        truth = load_box(variant(tmp, "truth.toml", 2.5, "shell", truth=True))
        t = time.perf_counter()
        tm = truth.build()
        tmodes = solve_modes(tm.model, n_modes=14)
        print(f"  test structure: {tm.model.n_dof} DOF, built and solved in {time.perf_counter() - t:.1f} s")
        points, dofs = read_points_csv(EXAMPLE.with_name("points.csv"))
        test = simulate_on_model(tm.model, tmodes, points, dofs, noise=Noise(0.2, 2.0, 0.0), seed=2, tol=0.02).modes
        test = test.subset(test.frequencies < 1500.0)
        model = load_box(variant(tmp, "model.toml", 5.0))
        prob = UpdateProblem(model, ["E_upper", "rho_upper", "h_side", "h_back"])
        cfgs = [prob.configuration(None, test, "freq", sigma=0.002 / np.sqrt(3) * test.frequencies)]
        t = time.perf_counter()
        res, before, after = run(prob, cfgs, "bounded", max_iter=5, tol_freq_pct=0.1)
        print(f"  update of {len(prob.names)} parameters on {test.n_modes} modes below 1.5 kHz: {res.iterations} "
              f"iterations in {time.perf_counter() - t:.1f} s ({res.reason}); max |df| "
              f"{before[0]['max_freq_error_pct']:.2f} % -> {after[0]['max_freq_error_pct']:.2f} %")
        r = res.p / prob.p0
        print(f"  upper plate E x {r[0]:.4f} (true 0.7: {100 * (r[0] / 0.7 - 1):+.2f} %), rho x {r[1]:.4f} (true 1.3: "
              f"{100 * (r[1] / 1.3 - 1):+.2f} %); rib heights x {np.round(r[2:], 4).tolist()} (the strips and the "
              "mesh)")


if __name__ == "__main__":
    main()
