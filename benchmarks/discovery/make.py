"""A drawn case (:mod:`cases`) made into files: the handed board.toml, points.csv, the test (UFF
with pcbdyn's noise model) of the truth solved in OpenSees on a mesh twice as fine as the model's,
and truth.json (the case, its exact frequencies). Made on demand from the seed and kept in a cache
outside git (``PCBDYN_DISCOVERY_CACHE``, default ``~/.cache/pcbdyn/discovery``); a folder made by the
same code for the same seed is reused.

    python benchmarks/discovery/make.py 0-9 [--cache DIR]     # boards; h0-9: housings (:mod:`housings`)

needs openseespy (``pip install -e .[discovery]``: an extra, not a core dependency).
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from cases import Case, draw  # noqa: E402
from seen import EXTRA_MODES, MIN_BENDING, bending_share  # noqa: E402
from toml_text import board_text  # noqa: E402

#: the truth is meshed this many times finer than the model
TRUTH_REFINEMENT = 2.0
#: damping of the simulated test's modes (written to the UFF; diagnose does not use it)
ZETA = 0.01


def cache_dir() -> Path:
    return Path(os.environ.get("PCBDYN_DISCOVERY_CACHE", Path.home() / ".cache" / "pcbdyn" / "discovery"))


def code_key() -> str:
    """A digest of the generator's own code: a cached case made by other code is made again."""
    h = hashlib.sha1()
    for name in ("cases.py", "toml_text.py", "make.py", "opensees_truth.py", "detectability.py", "seen.py"):
        h.update((HERE / name).read_bytes())
    return h.hexdigest()[:12]


def cached(folder: Path, key: str) -> bool:
    """Whether ``folder`` holds a case made by the code whose digest is ``key``."""
    tj = folder / "truth.json"
    return tj.exists() and json.loads(tj.read_text()).get("key") == key and (folder / "test.uff").exists()


def make(seed: int, cache: Path | None = None) -> Path:
    """The folder of case ``seed`` (made if missing): board.toml, points.csv, test.uff, truth.json."""
    folder = (cache or cache_dir()) / f"s{seed:04d}"
    tj, key = folder / "truth.json", code_key()
    if cached(folder, key):
        return folder
    folder.mkdir(parents=True, exist_ok=True)
    case = draw(seed)
    (folder / "board.toml").write_text(board_text(case))
    (folder / "truth.toml").write_text(board_text(case, truth=True, mesh_mm=case.mesh_mm / TRUTH_REFINEMENT))
    from detectability import effect_chi2

    frequencies = _solve_and_write(case, folder)
    tj.write_text(json.dumps({"key": key, "case": case.to_json(), "frequencies_hz": frequencies,
                              "signal_chi2": effect_chi2(case)}, indent=1))
    return folder


def truth_modes(case: Case, truth_toml: Path) -> tuple:
    """(frequencies [Hz], z shapes at the case's points (points x modes)) of the truth in OpenSees: the
    first ``case.test_modes`` modes a test in z sees (:data:`MIN_BENDING`)."""
    from opensees_truth import solve_opensees

    from pcbdyn.board import build_model, load_board
    from pcbdyn.fe.probe import model_probe

    tb = load_board(truth_toml)
    model = build_model(tb, None, tb.mesh_size, shared_mesh=True).model
    f, shapes = solve_opensees(model, case.test_modes + EXTRA_MODES, shell=case.shell)
    keep = np.flatnonzero(bending_share(shapes[:, :3]) >= MIN_BENDING)[:case.test_modes]
    points, dofs = measurement_points(case)
    read = model_probe(model, points.xyz, dofs.directions, tol=0.02).P
    return f[keep], np.asarray(read @ shapes[..., keep].reshape(-1, keep.size))


def measurement_points(case: Case) -> tuple:
    """(Points, Dofs) of the case's measurement points, each in +z."""
    from pcbdyn.testdata.data import Dofs, Points

    xy = 1e-3 * np.asarray(case.points, float)
    ids = np.arange(1, len(xy) + 1)
    return Points(ids, np.column_stack([xy, np.zeros(len(xy))])), Dofs(ids, np.tile([0.0, 0.0, 1.0], (len(ids), 1)))


def noisy_test(case: Case, f, z):
    """The test of modes (``f``, ``z`` at the points) as measured: pcbdyn's noise model at the case's levels."""
    from pcbdyn.fe.modal import Modes as ModelModes
    from pcbdyn.testdata.noise import Noise
    from pcbdyn.testdata.simulate import simulate_test

    points, dofs = measurement_points(case)
    modes = ModelModes(np.asarray(f, float), np.asarray(z, float), np.zeros((len(points.ids), 0)), None)
    return simulate_test(modes, points, dofs, np.eye(len(points.ids)), zeta=ZETA,
                         noise=Noise(frequency_pct=case.noise[0], shape_pct=case.noise[1]), seed=case.seed)


def _solve_and_write(case: Case, folder: Path) -> list:
    from pcbdyn.testdata.csvio import write_points_csv
    from pcbdyn.testdata.uff import write_uff

    f, z = truth_modes(case, folder / "truth.toml")
    write_points_csv(folder / "points.csv", *measurement_points(case))
    write_uff(folder / "test.uff", noisy_test(case, f, z))
    np.save(folder / "shapes_z.npy", z)
    return [float(v) for v in f]


def seeds(text: str) -> list:
    """'0-9,15' -> [0, ..., 9, 15]."""
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def case_names(text: str) -> list:
    """'0-9,h2-3' (or 'h2-h3') -> ['s0000', ..., 's0009', 'h0002', 'h0003']: boards (s) and housings (h) by seed."""
    out = []
    for part in text.split(","):
        kind = "h" if part.startswith("h") else "s"
        out += [f"{kind}{s:04d}" for s in seeds("-".join(end.lstrip("hs") for end in part.split("-")))]
    return out


def made(name: str, cache: Path | None = None) -> Path:
    """The folder of case ``name``, a board ``s0012`` or a housing ``h0012`` (:mod:`housings`), made if missing."""
    if name.startswith("h"):
        from housings import make as make_housing

        return make_housing(int(name[1:]), cache)
    return make(int(name[1:]), cache)


def main(argv=None):
    import argparse
    import time

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("seeds", help="e.g. 0-9 or 1000-1004,1010; housings h0-3")
    ap.add_argument("--cache", default=None)
    a = ap.parse_args(argv)
    for name in case_names(a.seeds):
        t0 = time.perf_counter()
        t = json.loads((made(name, Path(a.cache) if a.cache else None) / "truth.json").read_text())
        c = t["case"]
        structure = (f"{len(c['plates'])} plates, {len(c['ribs'])} ribs" if name.startswith("h") else
                     f"{c['hold']:<10} parts {len(c['parts']):>2}")
        print(f"{name} {structure}  {len(c['points']):>3} points  effects "
              f"{','.join(e['kind'] for e in c['effects']) or '-':<28} chi2 "
              f"{','.join(f'{v:.3g}' for v in t['signal_chi2']) or '-':<16} f1 {t['frequencies_hz'][0]:8.1f} Hz "
              f"({time.perf_counter() - t0:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
