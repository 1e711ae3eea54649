"""Repeated modal solves of one small model, as diagnosis and updating do them hundreds of times.

The six-part card (5.7k DOF, free-free: bending and membrane groups, six rigid-body modes) is
solved ``--repeats`` times with ``solve_modes(model, n_modes=14)`` on slightly changed matrices
(K and M scaled by 1 +- 1e-3 at random, the same sparsity pattern), each variant in a fresh
process:

- warm: what pcbdyn does (layout, block order and CHOLMOD symbolic analysis kept per pattern);
- cold: the same with nothing kept (every solve a first solve), the peer in the same run;
- threads: warm, but with the BLAS pools left at their own default (PCBDYN_BLAS_THREADS=0,
  OpenBLAS then starts one thread per core).

Each row gives the median wall and CPU time of one solve and the machine's load average; the
frequencies of every variant are checked against the first warm solve (relative difference).
``--profile`` prints where the warm solves spend their time (cProfile, top 15 by own time).

    python benchmarks/bench_repeated_solves.py [--repeats 40] [--profile]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

BOARD = Path(__file__).resolve().parents[1] / "examples" / "six_part_card" / "board.toml"


def measure(repeats: int, cold: bool, profile: bool) -> dict:
    import numpy as np

    import pcbdyn.board
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import solve_modes

    if cold:  # keep nothing between solves
        from pcbdyn.fe import blocks, linsolve

        blocks.LAYOUT_CACHE_SIZE = linsolve.SYMBOLIC_CACHE_SIZE = 0
    model = pcbdyn.board.build_model(pcbdyn.board.load_board(str(BOARD))).model
    K, M = assemble(model)
    rng = np.random.default_rng(1)
    scales = 1.0 + 1e-3 * rng.standard_normal((repeats + 1, 2))
    first = solve_modes(model, n_modes=14, K=K * scales[0, 0], M=M * scales[0, 1])
    walls, cpus, freqs = [], [], []
    prof = None
    if profile:
        import cProfile

        prof = cProfile.Profile()
        prof.enable()
    for a, b in scales[1:]:
        t, c = time.perf_counter(), time.process_time()
        modes = solve_modes(model, n_modes=14, K=K * a, M=M * b)
        walls.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
        freqs.append(modes.frequencies)
    if prof is not None:
        import io
        import pstats

        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(15)
        print(out.getvalue(), file=sys.stderr)
    ref = solve_modes(model, n_modes=14, K=K * scales[1, 0], M=M * scales[1, 1]).frequencies
    return {"wall_ms": 1e3 * float(np.median(walls)), "cpu_ms": 1e3 * float(np.median(cpus)),
            "first_f": first.frequencies.tolist(), "f": freqs[0].tolist(), "ref": ref.tolist(),
            "n_dof": model.n_dof}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=40)
    ap.add_argument("--profile", action="store_true", help="print the warm solves' profile")
    ap.add_argument("--one", choices=["warm", "cold"], help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(measure(args.repeats, args.one == "cold", args.profile)))
        return
    base = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    variants = [("warm", "warm", dict(base)), ("cold (nothing kept)", "cold", dict(base)),
                ("warm, BLAS default threads", "warm", dict(base, PCBDYN_BLAS_THREADS="0"))]
    print(f"six-part card, solve_modes(n_modes=14) x {args.repeats} on slightly changed K, M; {os.cpu_count()} cores")
    head = f"{'variant':<28} {'wall/solve':>11} {'CPU/solve':>10} {'load':>5} {'max |df/f|':>11}"
    print(head)
    print("-" * len(head))
    ref = None
    for name, mode, env in variants:
        cmd = [sys.executable, __file__, "--one", mode, "--repeats", str(args.repeats)]
        out = subprocess.run(cmd + ["--profile"] * (args.profile and mode == "warm" and ref is None),
                             capture_output=True, text=True, env=env, check=True)
        if out.stderr.strip():
            print(out.stderr)
        r = json.loads(out.stdout.strip().splitlines()[-1])
        ref = ref or r["ref"]
        df = max(abs(x / y - 1.0) for x, y in zip(r["ref"], ref))
        print(f"{name:<28} {r['wall_ms']:>9.1f}ms {r['cpu_ms']:>8.1f}ms {os.getloadavg()[0]:>5.1f} {df:>11.1e}",
              flush=True)


if __name__ == "__main__":
    main()
