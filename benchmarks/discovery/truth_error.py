"""The discovery truth's own discretisation error (issue 37): how far a case's truth, meshed
``make.TRUTH_REFINEMENT`` times finer than the model, lies from the converged frequencies.

The diagnosis takes its model's mesh error out (Richardson extrapolation to the converged limit,
:mod:`pcbdyn.diagnosis.budget`), so what it is judged against should be converged too: whatever the
truth's mesh leaves counts against the "error after" (acceptance: median <= 0.5 %). Estimated with
pcbdyn's shells on the truth's board.toml at its mesh h and at h / 2 (ASDShellQ4, which OpenSees solves
the truth with, agrees with pcbdyn's shells to 0.1 %), error(h) = 4/3 (f(h) / f(h/2) - 1) for
quadratic convergence, over the test's modes. Needs the cases made (:mod:`make`, cached).

    python benchmarks/discovery/truth_error.py 0-9

Measured (2026-11-28, dev seeds 0-9): the truth's largest error over a case's modes 0.09-0.51 %,
median case 0.30 %; median over all modes 0.15 %. The housing case (box_case.py) is meshed four
times finer for the same reason.
"""

from __future__ import annotations

import json
import re
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from make import cache_dir, seeds  # noqa: E402


def truth_error(folder: Path) -> np.ndarray:
    """[%] the estimated discretisation error of each test mode of the truth in ``folder``."""
    from pcbdyn.fe.modal import solve_modes
    from pcbdyn.problems import load_structure

    n = len(json.loads((folder / "truth.json").read_text())["frequencies_hz"])
    text = (folder / "truth.toml").read_text()
    mesh = re.search(r'mesh_size = "([0-9.]+) mm"', text)
    f = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in (1, 2):
            path = Path(tmp) / "truth.toml"
            path.write_text(text.replace(mesh.group(0), f'mesh_size = "{float(mesh.group(1)) / k:g} mm"'))
            s = load_structure(path)
            f.append(solve_modes(s.build(None, s.mesh_size, True).model, n_modes=n).frequencies[:n])
    return 100.0 * 4.0 / 3.0 * (f[0] / f[1] - 1.0)


def largest_error(folder: Path) -> float | None:
    """[%] the largest of :func:`truth_error` over the test modes of the board case in ``folder`` (None for a
    housing), kept in ``truth_error.json`` beside the case with the key of the truth it was computed for."""
    if not (folder / "truth.toml").exists() or (folder / "box.toml").exists():
        return None
    key = json.loads((folder / "truth.json").read_text())["key"]
    kept = folder / "truth_error.json"
    if kept.exists() and (old := json.loads(kept.read_text())).get("key") == key:
        return old["largest_pct"]
    from pcbdyn.report.files import write_json

    e = truth_error(folder)
    write_json(kept, {"key": key, "per_mode_pct": e.tolist(), "largest_pct": float(np.abs(e).max())})
    return float(np.abs(e).max())


def main(argv=None) -> None:
    worst, every = [], []
    for seed in seeds((argv or sys.argv[1:] or ["0-9"])[0]):
        folder = cache_dir() / f"s{seed:04d}"
        if not (folder / "truth.json").exists():
            print(f"s{seed:04d}: not made (benchmarks/discovery/make.py {seed})")
            continue
        e = truth_error(folder)
        worst.append(np.abs(e).max())
        every += np.abs(e).tolist()
        print(f"s{seed:04d}: truth's error per mode [%] {np.round(e, 2).tolist()}, largest {worst[-1]:.2f}", flush=True)
    if worst:
        print(f"{len(worst)} cases: largest per case {min(worst):.2f}-{max(worst):.2f} %, median case "
              f"{np.median(worst):.2f} %; median over all modes {np.median(every):.2f} %")


if __name__ == "__main__":
    main()
