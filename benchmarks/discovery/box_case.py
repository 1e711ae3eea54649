"""The housing case of issue 37: the example ribbed box (examples/ribbed_box) whose 80 g relay on the
back plate is left out of the box.toml handed to diagnose, with its declared values about 30 % off
(E and rho of the upper plate's shell, the rib heights: the first modes come out swapped), tested at the
example's 143 points in x, y and z. The truth is the example itself, meshed four times as fine and solved
in OpenSees; the noise is pcbdyn's (0.2 % frequencies, 2 % shapes).

    python benchmarks/discovery/box_case.py [--cache DIR] [--diagnose]

writes ``box80/`` in the discovery cache (box.toml, truth.toml, test.uff, truth.json); with ``--diagnose``
runs ``pcbdyn diagnose`` and ``pcbdyn update`` on the same files, as a user would, and prints the issue's
figures: the relay's distance and mass error, the largest frequency error as given, with the parameters
only and after, update's, and the wall times with the machine's load.

Measured (2026-11-28, the truth at 2.5 mm): relay found 0.7 mm off (the model's nearest node), 80.5 g
(+0.6 %); max |df| 29.7 % as given, 3.09 % parameters only, 0.95 % after; pcbdyn update 27.5 % ("cannot fit":
with the relay's mode among the data its fit finds another basin); diagnose 78-94 s, update 25-27 s wall.
Measured again (2026-11-30, load 0.2-0.4): the same figures but parameters only 2.86 %; diagnose 181 s (a second
search without the support placed from the relay's unpaired mode, and the diagnosis's own and update's fits of
the declared parameters one after the other), 135 s with update's fit on the spare core beside the diagnosis's
own; update 44-45 s. Again after the drilling rotations' stand-in inertia was lowered (bab79e3, load 0.6):
the same figures; diagnose 120 s, update 42 s. Again with the truth's lumped parts corrected (0f3f95d; the box
has none) and the support rule of d7a2f58: the same figures; diagnose 335 s, update 73 s at load 2.4 with three
benchmark cases running beside it. Again 2026-12-05 (b0fe0d4, the truth solved again, load 0.7): relay 0.7 mm off,
83.8 g (+4.7 %); 29.72 % as given, 2.80 % parameters only, 0.72 % after, update 27.43 %; diagnose 99 s, update
27 s; beside the relay one invented effect, a spring to ground of 94 N/mm 17 mm below it.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

from make import ZETA, cache_dir  # noqa: E402
from seen import EXTRA_MODES  # noqa: E402

EXAMPLE = ROOT / "examples" / "ribbed_box" / "box.toml"
#: the handed box's declared values (the example's, i.e. the truth's, in brackets)
HANDED = {"E": "50 GPa", "rho": "3500 kg/m^3", "h_side": "7 mm", "h_back": "13 mm", "h_upper_x": "7 mm"}
TRUTH = {"relay_mm": (100.0, 95.0), "plate": "back", "mass": 0.080, "E_upper": 70e9, "rho_upper": 2700.0,
         "h_side": 10e-3, "h_back": 10e-3, "h_upper_x": 10e-3}
TEST_MODES = 12
SHELL = "ASDShellQ4"
#: the truth's mesh, a quarter of the model's 10 mm: at 5 mm the relay's own mode is still 0.7 % above the
#: converged frequency (pcbdyn 567.8, 557.0, 553.0 Hz at 10, 5, 2.5 mm; OpenSees 557.3 Hz at 5 mm), and a
#: diagnosis that takes out its model's mesh error would be judged against the truth's
TRUTH_MESH = "2.5 mm"


def handed_text() -> str:
    """The example with the relay left out and its declared values off."""
    text = EXAMPLE.read_text()
    text, n = re.subn(r'\n\[\[masses\]\]\nname = "relay"\nplate = "back"\nat = \[[^\]]*\]\nmass = "80 g"\n', "\n", text)
    assert n == 1, "the relay block of the example box was not found"
    upper = text.index('name = "upper"')
    head, tail = text[:upper], text[upper:]
    # the plate's own E and rho (the quantities plates.upper.E and .rho): its ribs keep the aluminium they
    # inherit, as in the truth; a new material would move the ribs too, which no declared parameter reaches
    tail = tail.replace('material = "al"', f'material = "al"\nE = "{HANDED["E"]}"\nrho = "{HANDED["rho"]}"', 1)
    text = head + tail
    for ribs, h in (("left_v", HANDED["h_side"]), ("right_v", HANDED["h_side"]), ("back_h", HANDED["h_back"]),
                    ("upper_x", HANDED["h_upper_x"])):
        text = re.sub(rf'(name = "{ribs}\d"\n(?:[^\n]*\n)*?height = )"10 mm"', rf'\1"{h}"', text)
    return text


def make(cache: Path | None = None) -> Path:
    from opensees_truth import solve_opensees

    from pcbdyn.box import load_box
    from pcbdyn.fe.modal import Modes as ModelModes
    from pcbdyn.fe.probe import model_probe
    from pcbdyn.testdata.csvio import read_points_csv
    from pcbdyn.testdata.noise import Noise
    from pcbdyn.testdata.simulate import simulate_test
    from pcbdyn.testdata.uff import write_uff

    folder = (cache or cache_dir()) / "box80"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "box.toml").write_text(handed_text())  # cheap; the truth below is solved once
    made = folder / "truth.json"
    if made.exists() and (folder / "test.uff").exists() and json.loads(made.read_text()).get("mesh") == TRUTH_MESH:
        return folder
    truth = EXAMPLE.read_text().replace('mesh_size = "10 mm"', f'mesh_size = "{TRUTH_MESH}"')
    (folder / "truth.toml").write_text(truth)
    box = load_box(folder / "truth.toml")
    model = box.build().model
    f, shapes = solve_opensees(model, TEST_MODES + EXTRA_MODES, shell=SHELL)
    f, shapes = f[:TEST_MODES], shapes[..., :TEST_MODES]  # a test in x, y and z sees every mode
    points, dofs = read_points_csv(EXAMPLE.with_name("points.csv"))
    read = model_probe(model, points.xyz[points.index(dofs.point_ids)], dofs.directions, tol=0.02).P
    u = np.asarray(read @ shapes.reshape(-1, shapes.shape[-1]))
    test = simulate_test(ModelModes(f, u, np.zeros((u.shape[0], 0)), None), points, dofs, np.eye(u.shape[0]),
                         zeta=ZETA, noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=80)
    write_uff(folder / "test.uff", test)
    (folder / "truth.json").write_text(json.dumps({"truth": TRUTH, "frequencies_hz": f.tolist(), "shell": SHELL, "mesh": TRUTH_MESH},
                                                  indent=1))
    return folder


def _cli(folder: Path, command: str, out: Path) -> float:
    """Wall time [s] of ``pcbdyn <command>`` on the case, its JSON written to ``out``."""
    args = [sys.executable, "-m", "pcbdyn.cli", command, str(folder / "box.toml"), str(folder / "test.uff"),
            "--noise", "f=0.2,shape=2", "--json", str(out)]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    t0 = time.perf_counter()
    done = subprocess.run(args, cwd=ROOT, env=env, capture_output=True, text=True)
    if not out.exists():
        raise SystemExit(f"pcbdyn {command} wrote no JSON (exit {done.returncode}): {done.stderr[-800:]}")
    return time.perf_counter() - t0


def diagnose_and_update(folder: Path) -> None:
    """Print the figures of issue 37's housing case (see the module's docstring)."""
    truth = json.loads((folder / "truth.json").read_text())["truth"]
    load = os.getloadavg()[0]
    t_d = _cli(folder, "diagnose", folder / "diagnose.json")
    t_u = _cli(folder, "update", folder / "update.json")
    d, u = (json.loads((folder / f"{k}.json").read_text()) for k in ("diagnose", "update"))
    from pcbdyn.box import load_box

    plate = load_box(folder / "truth.toml").plate(truth["plate"])
    relay = 1e3 * np.asarray(plate.point(*(1e-3 * np.asarray(truth["relay_mm"]))), float)  # [mm] in the box's frame
    masses = [e for e in d["effects"] if e["type"] == "point_mass"]
    print(f"load average at the start {load:.1f} (2 cores)")
    for e in masses:
        print(f"point mass found {np.linalg.norm(np.array(e['at_mm']) - relay):.1f} mm from the relay, "
              f"{1e3 * e['magnitude']:.1f} g ({100 * (e['magnitude'] / truth['mass'] - 1):+.1f} %)")
    print(f"effects reported: {len(d['effects'])} ({len(masses)} point masses); the relay found within 15 mm and 30 %: "
          f"{any(np.linalg.norm(np.array(e['at_mm']) - relay) <= 15 and abs(e['magnitude'] / truth['mass'] - 1) <= 0.3 for e in masses)}")
    print("max |df| of the paired modes [%]: as given {:.2f}, parameters only {:.2f}, after {:.2f}; pcbdyn update "
          "{:.2f} ({})".format(d["before"]["max_freq_error_pct"], d["parameters_only"]["max_freq_error_pct"],
                               d["after"]["max_freq_error_pct"], u["after"]["max_freq_error_pct"], u["status"]))
    for n, v in d["parameters"].items():
        print(f"  {n:<10} declared {v['initial']:.4g}  final {v['final']:.4g}  truth {truth[n]:.4g}  update "
              f"{u['parameters'][n]['updated']:.4g}")
    print(f"wall: diagnose {t_d:.0f} s, update {t_u:.0f} s")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", default=None)
    ap.add_argument("--diagnose", action="store_true", help="run diagnose and update on the case and print the figures")
    a = ap.parse_args()
    out = make(Path(a.cache) if a.cache else None)
    print(out, json.loads((out / "truth.json").read_text())["frequencies_hz"])
    if a.diagnose:
        diagnose_and_update(out)
