"""A housing with three cards (examples/housed_cards with a second shelf 40 mm above the first) at 300k+ DOF:
building, 20 modes of the full system, and the same with every card reduced to its interface (Craig-Bampton,
40 fixed-interface modes each): time, peak memory and the reduction's error against the full model. Each
variant runs in a fresh process, so that its peak memory is its own.
Run: python benchmarks/bench_system.py [--mesh 3.1] [--modes 20]

Measured (2 cores shared with other jobs, 2026-11-27): 323,988 DOFs; full: build 114 s, 20 modes in 103 s,
peak 1.8 GB. Reduced (interfaces of 24, 948 and 948 DOFs): the reduction 319 s (once: each card's K_II
factor, 40 modes and constraint modes), then 130,278 DOFs solved in 38 s, peak 2.0 GB; largest frequency
error 1.1e-5 %. The reduction pays when the housing is solved again and again with the cards as they
are (updating the housing's parameters), not for one solve: its constraint modes, a dense n_I x n_C
block per card, cost more than the whole system's shift-invert Lanczos here.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import tomlkit  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "housed_cards"


def three_cards(folder: Path) -> Path:
    """The example box with a third card, a second shelf at z = 100 mm, in ``folder``."""
    for f in EXAMPLE.glob("*.toml"):
        shutil.copy(f, folder)
    doc = tomlkit.parse((folder / "box.toml").read_text())
    card = tomlkit.table()
    card.update({"name": "shelf2", "board": "card_guides.toml", "origin": ["0 mm", "10 mm", "100 mm"],
                 "u": [0, 1, 0], "v": [1, 0, 0]})
    doc["cards"].append(card)
    path = folder / "box.toml"
    path.write_text(tomlkit.dumps(doc))
    return path


def variant(path: str, mesh_mm: float, n_modes: int, reduce: int | None) -> dict:
    """Build and solve one variant in this process: its figures."""
    import numpy as np

    from pcbdyn.box import load_box
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.craig_bampton import craig_bampton, solve_reduced
    from pcbdyn.process import process_settings

    process_settings()
    t0 = time.perf_counter()
    system = load_box(path).build(mesh_size=mesh_mm * 1e-3)
    K, M = assemble(system.model)
    t1 = time.perf_counter()
    out = {"dofs": int(system.model.n_dof), "build_s": t1 - t0,
           "conforming": {n: pc.extra for n, pc in system.cards.items()}}
    if reduce:
        cb = craig_bampton(system.model, K, M, system.reduced_parts(reduce))
        t2 = time.perf_counter()
        modes = solve_reduced(cb, n_modes)
        out.update(reduce_s=t2 - t1, reduced_dofs=int(cb.K.shape[0]), interface=[int(p.C.size) for p in cb.parts])
    else:
        t2 = time.perf_counter()
        modes = system.solve(n_modes, K=K, M=M)
    out.update(solve_s=time.perf_counter() - t2, frequencies=np.asarray(modes.frequencies).tolist(),
               peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    return out


def fresh(path: Path, mesh_mm: float, n_modes: int, reduce: int | None) -> dict:
    out = subprocess.run([sys.executable, __file__, "--variant", str(path), "--mesh", str(mesh_mm), "--modes",
                          str(n_modes), "--reduce", str(reduce or 0)], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=float, default=3.1, help="housing mesh size [mm]; the cards' own 5 mm scale by the same factor (mesh / 10 mm)")
    ap.add_argument("--modes", type=int, default=20)
    ap.add_argument("--reduce", type=int, default=40, help="fixed-interface modes per card")
    ap.add_argument("--variant", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.variant:
        print(json.dumps(variant(a.variant, a.mesh, a.modes, a.reduce or None)))
        return
    with tempfile.TemporaryDirectory() as tmp:
        path = three_cards(Path(tmp))
        print(f"housing with three cards, housing mesh {a.mesh:g} mm, cards {5 * a.mesh / 10:g} mm, {a.modes} modes")
        full = fresh(path, a.mesh, a.modes, None)
        print(f"  full:    {full['dofs']:,} DOFs, build {full['build_s']:.1f} s, solve {full['solve_s']:.1f} s, "
              f"peak {full['peak_mb']:.0f} MB")
        red = fresh(path, a.mesh, a.modes, a.reduce)
        print(f"  reduced ({a.reduce} modes per card, interfaces of {red['interface']} DOFs): build "
              f"{red['build_s']:.1f} s, reduction {red['reduce_s']:.1f} s (once), then {red['reduced_dofs']:,} "
              f"DOFs solved in {red['solve_s']:.1f} s, peak {red['peak_mb']:.0f} MB")
        err = [100 * (r / f - 1) for r, f in zip(red["frequencies"], full["frequencies"])]
        print(f"  reduction error on the first {len(err)} modes: largest {max(map(abs, err)):.2g} %")
        print("  frequencies [Hz]: " + ", ".join(f"{f:.1f}" for f in full["frequencies"]))
        print(f"  housing nodes tied between card nodes (gmsh's quad split): {full['conforming']}")


if __name__ == "__main__":
    main()
