"""Sensor placement of ``pcbdyn pretest`` against SDynPy's ``by_effective_independence`` (issue 41).

Cases: the six-part card's 81 grid points along z, 12 sensors for 7 modes; the example box's grid of
twice its mesh size over every plate, 12 triaxial sensors for 12 modes (SDynPy's bundles of three rows).
Printed per method: the chosen candidates, log det(Phi^T Phi), the largest off-diagonal AutoMAC and the
time. SDynPy is GPL: it is never a dependency of pcbdyn; it runs in its own environment, given by the
SDYNPY_PYTHON variable (default /tmp/sdynpy_venv/bin/python), made with

    python3 -m venv /tmp/sdynpy_venv && /tmp/sdynpy_venv/bin/pip install sdynpy

The shape matrices are handed over as .npy files; without that environment the SDynPy column says why.

Run: python benchmarks/bench_pretest_sensors.py
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from pcbdyn.problems import load_structure  # noqa: E402
from pcbdyn.problems.pretest import pretest_model, sensor_directions  # noqa: E402
from pcbdyn.problems.pretest_points import candidate_grid, read_candidates  # noqa: E402
from pcbdyn.updating import design  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SDYNPY = os.environ.get("SDYNPY_PYTHON", "/tmp/sdynpy_venv/bin/python")
RUNNER = """
import json, sys, time, numpy as np
from sdynpy.fem.sdynpy_dof import by_effective_independence
phi = np.load(sys.argv[1]); t0 = time.perf_counter()
keep = by_effective_independence(int(sys.argv[2]), phi)
print(json.dumps({"keep": np.asarray(keep).tolist(), "seconds": time.perf_counter() - t0}))
"""


def sdynpy(phi: np.ndarray, n: int):
    """(chosen bundle indices, seconds) from SDynPy, or (None, why not)."""
    if not Path(SDYNPY).is_file():
        return None, f"no SDynPy environment at {SDYNPY} (see the module docstring)"
    with tempfile.TemporaryDirectory() as tmp:
        np.save(Path(tmp) / "phi.npy", phi)
        (Path(tmp) / "run.py").write_text(RUNNER)
        env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "MPLBACKEND": "Agg"}
        r = subprocess.run([SDYNPY, str(Path(tmp) / "run.py"), str(Path(tmp) / "phi.npy"), str(n)],
                           capture_output=True, text=True, env=env)
    if r.returncode != 0:
        return None, "SDynPy failed: " + (r.stderr.strip().splitlines() or ["?"])[-1]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    return np.array(out["keep"]), out["seconds"]


def case(title: str, toml: Path, cand, n_sensors: int, triaxial: bool) -> None:
    structure = load_structure(toml)
    model = pretest_model(structure, [])
    cand = cand(structure)
    dirs, point, _ = sensor_directions(cand, triaxial)
    Phi = np.asarray(model.read(cand.xyz[point], dirs) @ model.phi)
    r = 3 if triaxial else 1
    bundles = Phi.reshape(len(cand), r, -1)

    def figures(chosen):
        rows = bundles[np.asarray(chosen)].reshape(-1, Phi.shape[1])
        G = rows.T @ rows
        return design.log_det(G), float(design.automac_offdiag(G))

    print(f"\n{title}: {len(cand)} candidates{' (x, y, z each)' if triaxial else ''}, {n_sensors} sensors, "
          f"{model.lam.size} modes")
    print(f"{'method':<34} {'log det':>9} {'AutoMAC max':>12} {'time [s]':>9}  chosen")
    t0 = time.perf_counter()
    efi = design.effective_independence(Phi, n_sensors, point)
    t_efi = time.perf_counter() - t0
    t0 = time.perf_counter()
    guarded = design.choose_sensors(Phi, n_sensors, point, 0.25)
    t_guard = time.perf_counter() - t0
    keep, t_sd = sdynpy(bundles if triaxial else Phi, n_sensors)
    rows = [("pcbdyn EfI", efi, t_efi), ("pcbdyn EfI + AutoMAC guard (0.25)", guarded.chosen, t_guard)]
    if keep is not None:
        rows.append(("SDynPy by_effective_independence", keep, t_sd))
    for name, chosen, t in rows:
        ld, am = figures(chosen)
        print(f"{name:<34} {ld:9.3f} {am:12.3f} {t:9.3f}  {sorted(int(cand.ids[i]) for i in chosen)}")
    if keep is None:
        print(f"SDynPy: {t_sd}")
    else:
        print(f"same set as SDynPy: {set(np.asarray(efi).tolist()) == set(keep.tolist())}")


def main() -> None:
    card = ROOT / "examples/six_part_card"
    case("six-part card, 81 grid points along z", card / "board.toml",
         lambda s: read_candidates(s, card / "points.csv"), 12, False)
    box = ROOT / "examples/ribbed_box/box.toml"
    case("ribbed box, grid of 20 mm on every plate, triaxial", box, lambda s: candidate_grid(s, 2 * s.mesh_size),
         12, True)


if __name__ == "__main__":
    main()
