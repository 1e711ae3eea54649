"""Modal benchmark: square quad4 plates from ~1k to ~1M DOF, first 20 modes, each beside its peers.

For each size, in a fresh subprocess (so that the peak resident memory is that size's own):
assembly, constraint reduction and solve_modes (layout, factorisation, eigensolution) times, the
process CPU time and peak RSS, and the machine's load average when the row was measured. Peers,
each in the same run and on the same mesh: CalculiX 2.20 (``--calculix``: S4 shells,
``*FREQUENCY``, as a whole process, its output parsed for f1 and f20) and plain SciPy (``--eigsh``:
``eigsh(K, 20, M, sigma)`` on pcbdyn's constrained matrices, its own SuperLU shift-invert).

    python benchmarks/bench_modal.py [--sizes 12 40 70 100 136] [--support clamped|simple|free]
                                     [--tilted] [--calculix] [--eigsh] [--threads 1]

Targets (issue 23): 112k DOF (``--sizes 136``), simply supported, 20 modes, at least 15x faster
than CalculiX in wall and CPU time; 1M DOF (``--sizes 408``), flat and ``--tilted``, <= 60 s and
<= 12 GB on a 2-core machine. The plate is a 0.16 m square FR4-like board, 1.6 mm thick, held at
its edge nodes: clamped (all six DOFs; f1 = 355.6 Hz), simply supported (translations; f1 = 195.1
Hz from Kirchhoff theory) or free. A flat plate in the xy plane splits into uncoupled bending and
membrane blocks that solve_modes solves apart; ``--tilted`` rotates it out of the coordinate
planes, so that the full 6-DOF/node system is solved at once (a housing's case).
"wall"/"CPU" are seconds of the measured part; the CalculiX and whole-process figures come from
the operating system's accounting of the child process (wait4). ``--threads`` is pcbdyn's BLAS
thread limit (PCBDYN_BLAS_THREADS); CalculiX keeps its own defaults. CalculiX is optional (Debian
package ``calculix-ccx``): without ``ccx`` on the PATH its columns say so.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

A_SIDE, THICK = 0.16, 1.6e-3
MATERIAL = dict(E=22e9, nu=0.15, rho=1900.0)
N_MODES = 20


def plate(n: int, tilted: bool, support: str):
    """The pcbdyn model and the held edge nodes / DOFs of the benchmark plate."""
    import numpy as np

    from pcbdyn.fe.generate import rectangle, rectangle_edges
    from pcbdyn.fe.model import Model
    from pcbdyn.fe.properties import ShellProperty

    nodes, quads = rectangle(A_SIDE, A_SIDE, n, n)
    edge = np.unique(np.concatenate(list(rectangle_edges(nodes, A_SIDE, A_SIDE).values())))
    if tilted:  # out of the coordinate planes: bending and membrane DOFs no longer uncouple
        c, s = np.cos(0.5), np.sin(0.5)
        nodes = nodes @ np.array([[1, 0, 0], [0, c, s], [0, -s, c]]) @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    model = Model(nodes)
    model.add("plate", "quad4", quads, ShellProperty(t=THICK, **MATERIAL))
    dofs = {"clamped": [0, 1, 2, 3, 4, 5], "simple": [0, 1, 2], "free": []}[support]
    if dofs:
        model.fix(edge, dofs)
    model.free = support == "free"
    return model, quads, edge, dofs


def run_pcbdyn(n: int, tilted: bool, support: str, eigsh: bool) -> dict:
    """One size, measured in this (fresh) process."""
    from pcbdyn.process import process_settings
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import reduced_system, solve_modes

    process_settings()  # as the command line does: thread limits, memory pages
    model, *_ = plate(n, tilted, support)
    t0, c0 = time.perf_counter(), time.process_time()
    K, M = assemble(model)
    t1, c1 = time.perf_counter(), time.process_time()
    modes = solve_modes(model, n_modes=N_MODES, K=K, M=M)  # reduction, layout, factor, Lanczos
    t2, c2 = time.perf_counter(), time.process_time()
    out = {
        "dof": model.n_dof, "assembly_s": t1 - t0, "modes_s": t2 - t1, "modes_cpu_s": c2 - c1,
        "wall_s": t2 - t0, "cpu_s": c2 - c0,
        "f1": float(modes.frequencies[0]), "f20": float(modes.frequencies[-1]),
        "peak_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }
    if eigsh:  # the peer: SciPy's own shift-invert (SuperLU, COLAMD) on the same matrices
        import numpy as np
        import scipy.sparse.linalg as spla

        _, Kr, Mr = reduced_system(model, K, M)
        dk, dm = Kr.diagonal(), Mr.diagonal()
        sigma = -1e-9 * float(np.median(dk[dm > 0] / dm[dm > 0]))
        t3, c3 = time.perf_counter(), time.process_time()  # compared with solve_modes (both after assembly)
        lam = np.sort(spla.eigsh(Kr.tocsc(), k=N_MODES + 6 * model.free, M=Mr.tocsc(), sigma=sigma,
                                 return_eigenvectors=False))
        out.update(eigsh_s=time.perf_counter() - t3, eigsh_cpu_s=time.process_time() - c3,
                   eigsh_f20=float(np.sqrt(max(lam[-1], 0.0)) / (2 * np.pi)))
    return out


def calculix_input(n: int, tilted: bool, support: str) -> str:
    """The same plate for CalculiX: S4 shells, the same held DOFs, 20 modes."""
    model, quads, edge, dofs = plate(n, tilted, support)
    lines = ["*HEADING", "pcbdyn benchmark plate", "*NODE, NSET=NALL"]
    lines += [f"{i + 1}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in enumerate(model.nodes)]
    lines.append("*ELEMENT, TYPE=S4, ELSET=EALL")
    lines += [f"{e + 1}, {a + 1}, {b + 1}, {c + 1}, {d + 1}" for e, (a, b, c, d) in enumerate(quads)]
    if dofs:
        lines.append("*NSET, NSET=EDGE")
        lines += [", ".join(str(v + 1) for v in edge[i:i + 16]) for i in range(0, edge.size, 16)]
        lines += ["*BOUNDARY", f"EDGE, {dofs[0] + 1}, {dofs[-1] + 1}"]
    lines += ["*MATERIAL, NAME=FR4", "*ELASTIC", f"{MATERIAL['E']:.6g}, {MATERIAL['nu']}", "*DENSITY",
              f"{MATERIAL['rho']}", "*SHELL SECTION, ELSET=EALL, MATERIAL=FR4", f"{THICK}",
              "*STEP", "*FREQUENCY", f"{N_MODES + 6 * (support == 'free')}", "*END STEP"]
    return "\n".join(lines) + "\n"


def run_calculix(n: int, tilted: bool, support: str) -> dict:
    """CalculiX on the same plate, as a whole process: wall, CPU and peak RSS from wait4."""
    ccx = shutil.which("ccx")
    if ccx is None:
        return {"error": "ccx not found (apt-get install calculix-ccx)"}
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "plate.inp"), "w") as f:
            f.write(calculix_input(n, tilted, support))
        t0 = time.perf_counter()
        proc = subprocess.Popen([ccx, "-i", "plate"], cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        try:
            with open(os.path.join(tmp, "plate.dat")) as f:
                dat = f.read()
        except FileNotFoundError:
            dat = ""
    # eigenvalue table rows: mode, eigenvalue, omega (rad/time), omega (cycles/time), ...
    rows = re.findall(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", dat.split("P A R T I C I P")[0], re.MULTILINE)
    f = [float(r[3]) for r in rows]
    f = [v for v in f if v > 1.0][:N_MODES]  # a free plate's six rigid modes first
    if proc.returncode != 0 or not f:
        return {"error": f"ccx exit {proc.returncode}, no eigenvalues read"}
    return {"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime, "peak_MB": usage.ru_maxrss / 1024.0,
            "f1": f[0], "f20": f[-1]}


def child(argv: list[str], env: dict) -> tuple[dict, float]:
    """Run this script on one size in a fresh process; its JSON and the load average at its end."""
    out = subprocess.run([sys.executable, __file__, *argv], capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1]), os.getloadavg()[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[12, 40, 70, 100, 136], help="elements per side")
    ap.add_argument("--support", choices=["clamped", "simple", "free"], default="clamped")
    ap.add_argument("--tilted", action="store_true", help="rotate the plate out of the coordinate planes")
    ap.add_argument("--calculix", action="store_true", help="run CalculiX on every size (its peer)")
    ap.add_argument("--eigsh", action="store_true", help="run plain SciPy eigsh on pcbdyn's matrices")
    ap.add_argument("--threads", type=int, default=1, help="pcbdyn's BLAS thread limit")
    ap.add_argument("--one", choices=["pcbdyn", "calculix"], help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        n = args.sizes[0]
        out = run_pcbdyn(n, args.tilted, args.support, args.eigsh) if args.one == "pcbdyn" else run_calculix(
            n, args.tilted, args.support)
        print(json.dumps(out))
        return
    env = dict(os.environ, PCBDYN_BLAS_THREADS=str(args.threads))
    flags = ["--support", args.support] + ["--tilted"] * args.tilted
    print(f"plate {A_SIDE} m, t = {THICK * 1e3} mm, {args.support}{', tilted' if args.tilted else ''}; "
          f"{N_MODES} modes; pcbdyn BLAS threads {args.threads}; {os.cpu_count()} cores")
    head = (f"{'mesh':>9} {'DOF':>8} {'assembly':>9} {'modes':>8} {'wall':>8} {'CPU':>8} {'peak MB':>8} "
            f"{'f1 Hz':>8} {'f20 Hz':>8} {'load':>5}  peer")
    print(head)
    print("-" * len(head))
    for n in args.sizes:
        r, load = child(["--one", "pcbdyn", "--sizes", str(n)] + flags + ["--eigsh"] * args.eigsh, env)
        print(f"{n:>4}x{n:<4} {r['dof']:>8} {r['assembly_s']:>8.2f}s {r['modes_s']:>7.2f}s {r['wall_s']:>7.2f}s "
              f"{r['cpu_s']:>7.2f}s {r['peak_MB']:>8.0f} {r['f1']:>8.2f} {r['f20']:>8.2f} {load:>5.1f}  pcbdyn",
              flush=True)
        if args.eigsh:
            print(f"{'':>37} {r['eigsh_s']:>7.2f}s {r['eigsh_cpu_s']:>7.2f}s {'':>8} {'':>8} {r['eigsh_f20']:>8.2f} "
                  f"{'':>5}  SciPy eigsh (SuperLU): pcbdyn {r['eigsh_s'] / r['modes_s']:.1f}x faster (wall), "
                  f"{r['eigsh_cpu_s'] / r['modes_cpu_s']:.1f}x (CPU)", flush=True)
        if args.calculix:
            c, load = child(["--one", "calculix", "--sizes", str(n)] + flags, dict(os.environ))
            if "error" in c:
                print(f"{'':>19} CalculiX: {c['error']}")
                continue
            print(f"{'':>28} {c['wall_s']:>7.2f}s {c['cpu_s']:>7.2f}s {c['peak_MB']:>8.0f} {c['f1']:>8.2f} "
                  f"{c['f20']:>8.2f} {load:>5.1f}  CalculiX S4 (whole process): pcbdyn "
                  f"{c['wall_s'] / r['wall_s']:.1f}x faster (wall), {c['cpu_s'] / r['cpu_s']:.1f}x (CPU)", flush=True)


if __name__ == "__main__":
    main()
