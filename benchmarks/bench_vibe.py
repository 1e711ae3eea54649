"""Vibration verdict benchmark (issue 24): the wedge-locked six-part card under the GEVS
qualification level, at its own mesh and at meshes two and three times finer: DOFs, modes found,
the wall time of the modal solve and of the assessment, peak memory, and how the worst part's RMS
displacement and life move with the mesh.

    python benchmarks/bench_vibe.py [--refine 1,2,3]
"""

from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def one(refine: int) -> dict:
    from pcbdyn.board import build_model, load_board
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import solve_modes
    from pcbdyn.vibration import analysis_band, assess, named_psd, parse_damping

    board = load_board(ROOT / "examples" / "wedge_locked" / "board.toml")
    psd = named_psd("gevs-qual")
    t0 = time.perf_counter()
    bm = build_model(board, mesh_size=board.mesh_size / refine)
    K, M = assemble(bm.model)
    modes = solve_modes(bm.model, n_modes=150, f_max=analysis_band(psd), K=K, M=M)
    t_solve = time.perf_counter() - t0
    t0 = time.perf_counter()
    a = assess(board, bm, modes, K, M, psd, parse_damping("steinberg"), duration=psd.duration)
    t_assess = time.perf_counter() - t0
    worst = a.parts[0]
    return {"mesh_mm": board.mesh_size / refine * 1e3, "dofs": bm.model.n_dof, "modes": modes.frequencies.size,
            "grid": a.grid.size, "solve_s": t_solve, "assess_s": t_assess, "worst": worst.ref,
            "z_rms_mm": worst.z_rms_m * 1e3, "life_h": worst.life_h,
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--refine", default="1,2,3", help="mesh refinement factors")
    args = ap.parse_args()
    print(f"{'mesh [mm]':>9} {'DOFs':>7} {'modes':>5} {'grid':>5} {'solve [s]':>9} {'assess [s]':>10} "
          f"{'worst':>5} {'z_rms [mm]':>10} {'life [h]':>8} {'peak RSS [MB]':>13}")
    for k in (int(x) for x in args.refine.split(",")):
        r = one(k)
        print(f"{r['mesh_mm']:9.2f} {r['dofs']:7d} {r['modes']:5d} {r['grid']:5d} {r['solve_s']:9.2f} "
              f"{r['assess_s']:10.2f} {r['worst']:>5} {r['z_rms_mm']:10.4f} {r['life_h']:8.3f} {r['peak_rss_mb']:13.0f}")


if __name__ == "__main__":
    main()
