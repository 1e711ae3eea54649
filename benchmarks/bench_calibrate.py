"""Library calibration on simulated boards (issue 19) over several random draws: the acceptance case of
tests/calibration/test_simulated.py (three boards, PGA/CQFP/JLCC parts scattering 3 % part to part,
truth meshed twice as fine, 2 % shape / 0.2 % frequency noise) repeated with other seeds, so that the
spread of the errors and of z = (value - true mean) / std is seen, not one draw. Per seed: each family's
error [%] and z for the library of three pooled runs and for one joint run, the unseen fourth board's
max frequency error below 1 kHz with each library, and the wall time of the calibrations.

    python benchmarks/bench_calibrate.py [--seeds 0,10,20,30,40] [--method freq] [--out out/calibrate_bench]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "calibration"))

from click.testing import CliRunner  # noqa: E402

import sim_boards as sb  # noqa: E402
from pcbdyn.cli import main  # noqa: E402
from test_simulated import BOARDS, predict_unseen  # noqa: E402


def calibrate(args, js):
    r = CliRunner().invoke(main, ["calibrate", *map(str, args), "--json", str(js)])
    if r.exit_code != 0:
        raise SystemExit(r.output)
    return json.loads(js.read_text())["families"]


def main_(seeds, method, out):
    print(f"{'seed':>4} {'library':>6} " + " ".join(f"{f + ' err/z':>15}" for f in sb.TRUE_MM)
          + f" {'b4 max|df| [%]':>15} {'time [s]':>9}")
    for seed in seeds:
        d = out / f"seed{seed}"
        d.mkdir(parents=True, exist_ok=True)
        case = {n: sb.write_case(d, n, seed=seed + k) for k, n in enumerate(BOARDS + ["b4"])}
        (d / "calibration.toml").write_text("".join(f'[[boards]]\nboard = "{n}.toml"\ntest = "{n}_test.uff"\n\n'
                                                    for n in BOARDS))
        for label in ("seq", "joint"):
            lib = d / f"lib_{label}"
            t0 = time.perf_counter()
            if label == "seq":
                for n in BOARDS:
                    fams = calibrate([*case[n][:2], "--library", lib, "--method", method, "--noise", "f=0.2,shape=2"],
                                     d / f"{n}.json")
            else:
                fams = calibrate(["--joint", d / "calibration.toml", "--library", lib, "--method", method],
                                 d / "joint.json")
            dt = time.perf_counter() - t0
            cells = []
            for fam, true in sb.TRUE_MM.items():
                v, s = fams[fam]["equivalent_thickness_m"] * 1e3, fams[fam]["std_m"] * 1e3
                cells.append(f"{100 * (v / true - 1):+6.2f}/{(v - true) / s:+5.2f}")
            err = predict_unseen(d, case["b4"][0], lib, label)
            print(f"{seed:>4} {label:>6} " + " ".join(f"{c:>15}" for c in cells) + f" {err:>15.2f} {dt:>9.1f}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0,10,20,30,40")
    ap.add_argument("--method", default="freq", choices=["freq", "qms", "fbm"])
    ap.add_argument("--out", type=Path, default=Path("out/calibrate_bench"))
    a = ap.parse_args()
    main_([int(s) for s in a.seeds.split(",")], a.method, a.out)
