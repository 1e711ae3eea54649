"""Modal benchmark: square quad4 plates from ~1k to ~150k DOF, first 20 modes.

For each size, in a fresh subprocess (so that the peak resident memory is that size's own):
assembly time, constraint reduction time, solve_modes time (reduction, factorisation and
eigensolution) and peak RSS. Target (issue 2): 100k DOF, 20 modes in <= 5 s and <= 2 GB on a 2-core machine.

    python benchmarks/bench_modal.py [--sizes 12 40 70 100 128 157] [--threads 1] [--tilted] [--free]

The plate is a 0.16 m square FR4-like board, 1.6 mm thick, with all DOFs of its edge nodes held
(clamped: f1 = 355.6 Hz from lambda^2 = 35.985), or free (--free). A flat plate in the xy plane
splits into uncoupled bending and membrane blocks that solve_modes solves apart; --tilted rotates
it out of the coordinate planes, so that the full 6-DOF/node system is solved at once.
"20 modes" is wall time, "(CPU)" the process CPU time of the same call (the steadier figure on a
shared machine). ``--threads`` sets the BLAS threads CHOLMOD's supernodal kernels may use (threadpoolctl).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time


def one(n: int, threads: int, tilted: bool, free: bool) -> dict:
    import numpy as np
    from threadpoolctl import threadpool_limits

    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.generate import rectangle, rectangle_edges
    from pcbdyn.fe.modal import reduced_system, solve_modes
    from pcbdyn.fe.model import Model
    from pcbdyn.fe.properties import ShellProperty

    a = 0.16
    with threadpool_limits(limits=threads):
        nodes, quads = rectangle(a, a, n, n)
        edges = rectangle_edges(nodes, a, a)
        if tilted:  # out of the coordinate planes: bending and membrane DOFs no longer uncouple
            c, s = np.cos(0.5), np.sin(0.5)
            nodes = nodes @ np.array([[1, 0, 0], [0, c, s], [0, -s, c]]) @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
        model = Model(nodes)
        model.add("plate", "quad4", quads, ShellProperty(E=22e9, nu=0.15, rho=1900.0, t=1.6e-3))
        if free:
            model.free = True
        else:
            model.fix(np.unique(np.concatenate(list(edges.values()))))
        t0 = time.perf_counter()
        K, M = assemble(model)
        t1 = time.perf_counter()
        _, Kr, Mr = reduced_system(model, K, M)
        t2 = time.perf_counter()
        c2 = time.process_time()
        modes = solve_modes(model, n_modes=20, K=K, M=M)  # includes its own reduction
        t3 = time.perf_counter()
        c3 = time.process_time()
    return {
        "mesh": f"{n}x{n}",
        "dof": model.n_dof,
        "free_dof": Kr.shape[0],
        "assembly_s": t1 - t0,
        "reduction_s": t2 - t1,
        "modes_s": t3 - t2,
        "modes_cpu_s": c3 - c2,
        "f1_Hz": float(modes.frequencies[0]),
        "f20_Hz": float(modes.frequencies[-1]),
        "peak_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[12, 40, 70, 100, 128, 157], help="elements per side")
    ap.add_argument("--threads", type=int, default=1, help="BLAS threads for the factorisation")
    ap.add_argument("--tilted", action="store_true", help="rotate the plate out of the coordinate planes")
    ap.add_argument("--free", action="store_true", help="free-free plate (6 rigid-body modes) instead of clamped edges")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one is not None:
        print(json.dumps(one(args.one, args.threads, args.tilted, args.free)))
        return
    env = dict(os.environ, OPENBLAS_NUM_THREADS=str(args.threads), OMP_NUM_THREADS=str(args.threads))
    head = f"{'mesh':>9} {'DOF':>8} {'free':>8} {'assembly':>9} {'reduction':>9} {'20 modes':>9} {'(CPU)':>8} {'peak MB':>8} {'f1 Hz':>9} {'f20 Hz':>9}"
    print(head)
    print("-" * len(head))
    for n in args.sizes:
        out = subprocess.run(
            [sys.executable, __file__, "--one", str(n), "--threads", str(args.threads)] + ["--tilted"] * args.tilted + ["--free"] * args.free,
            capture_output=True, text=True, env=env, check=True,
        )
        r = json.loads(out.stdout.strip().splitlines()[-1])
        print(
            f"{r['mesh']:>9} {r['dof']:>8} {r['free_dof']:>8} {r['assembly_s']:>8.2f}s {r['reduction_s']:>8.2f}s "
            f"{r['modes_s']:>8.2f}s {r['modes_cpu_s']:>7.2f}s {r['peak_MB']:>8.0f} {r['f1_Hz']:>9.2f} {r['f20_Hz']:>9.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
