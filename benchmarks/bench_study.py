"""Benchmark: success-ratio study on the thesis' simulated free PCB (42 thicknesses, QMS, first
7 modes): 20 shots x 8 noise levels x 3 methods, all cores, automatic rank. Target: under 60 s
here.

Run: OPENBLAS_NUM_THREADS=1 python benchmarks/bench_study.py
"""

import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from pcbdyn.problems.cases import SimulatedFreePCB  # noqa: E402
from pcbdyn.updating.study import run_study, summarise  # noqa: E402

LEVELS = [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0]
METHODS = ("tls-qrf", "svd-qr", "min-norm")


def main():
    t0 = time.perf_counter()
    case = SimulatedFreePCB()
    t_case = time.perf_counter() - t0
    workers = os.cpu_count() or 1
    t1 = time.perf_counter()
    df = run_study(case, LEVELS, shots=20, methods=METHODS, kinds=("qms",), workers=workers,
                    progress=False)
    t_run = time.perf_counter() - t1
    table = summarise(df).pivot_table(index="level_pct", columns="method", values="mean").round(1)
    print(table.to_string())
    print(f"case build (FE, Guyan, 42 sensitivities): {t_case:.2f} s")
    print(f"study: {len(df)} localisations ({20 * len(LEVELS)} noisy equation sets x {len(METHODS)} methods) "
          f"on {workers} processes: {t_run:.2f} s")
    print(f"total: {t_case + t_run:.2f} s (target < 60 s)")
    t2 = time.perf_counter()
    run_study(case, LEVELS, shots=20, methods=METHODS, kinds=("frf", "frf+pbc"), rank=-1,
              workers=workers, progress=False)
    print(f"same study with FRF and FRF+PBC equations: {time.perf_counter() - t2:.2f} s")
    bundled()


def bundled() -> None:
    """``pcbdyn study examples/studies/study.toml`` as a user runs it (issue 23 target: <= 60 s)."""
    import shutil
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as d:
        shutil.copy(root / "examples/studies/study.toml", d)
        load, t0 = os.getloadavg()[0], time.perf_counter()
        before = os.times()
        subprocess.run([sys.executable, "-m", "pcbdyn.cli", "study", str(Path(d) / "study.toml"), "--quiet",
                        "--out", str(Path(d) / "study_out")],
                       check=True, capture_output=True)
        after = os.times()
        cpu = (after.children_user + after.children_system) - (before.children_user + before.children_system)
        print(f"pcbdyn study examples/studies/study.toml: {time.perf_counter() - t0:.1f} s wall, {cpu:.1f} s CPU "
              f"(load {load:.1f}; target <= 60 s)")


if __name__ == "__main__":
    main()
