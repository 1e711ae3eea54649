"""Issue 7 acceptance on hold-out data (:mod:`holdout_cases`): ``pcbdyn diagnose`` on modal tests
computed by another FE code (OpenSees, Kirchhoff plate elements) on a mesh four times finer than
the model's, with the bench's noise (0.2 % frequency, 2 % shape), judged as the bench is
(:func:`test_diagnose_bench.judge`): the effect's type, place and size, the error after, and no
effect on noise-only data. On noise-only data the two codes' models still differ (plate theory,
how a body with rotary inertia is attached) by more than the stated noise where configurations
carry large masses, so diagnose may say the residual is not noise (``noise_only`` false), but it
must not invent an effect for it."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_cases as bc  # noqa: E402
import holdout_cases as hc  # noqa: E402
from test_diagnose_bench import judge, run_diagnose  # noqa: E402


def make_holdout(case, folder: Path):
    """(board.toml handed to diagnose, [UFF per configuration], truth dict) in ``folder``: the
    stored clean modes of ``holdout/<case>.json`` with the case's noise (fixed seeds)."""
    from pcbdyn.fe.modal import Modes as ModelModes
    from pcbdyn.testdata.data import Dofs, Points
    from pcbdyn.testdata.noise import Noise
    from pcbdyn.testdata.simulate import simulate_test
    from pcbdyn.testdata.uff import write_uff

    data = json.loads((hc.HERE / f"{case.name}.json").read_text())
    folder.mkdir(parents=True, exist_ok=True)
    board = folder / "board.toml"
    board.write_text(bc.handed_text(case))
    xy = 1e-3 * np.asarray(data["points_mm"], float)
    ids = np.arange(1, len(xy) + 1)
    points = Points(ids, np.column_stack([xy, np.zeros(len(xy))]))
    dofs = Dofs(ids, np.tile([0.0, 0.0, 1.0], (len(ids), 1)))
    uffs = []
    for k, cfg in enumerate(case.configs):
        c = data["configs"][cfg or "base"]
        shapes = np.asarray(c["shapes_z"], float)
        modes = ModelModes(np.asarray(c["frequencies_hz"], float), shapes, np.zeros((len(ids), 0)), None)
        test = simulate_test(modes, points, dofs, np.eye(len(ids)), zeta=0.01,
                             noise=Noise(frequency_pct=case.noise[0], shape_pct=case.noise[1]),
                             seed=1000 * case.seed + k)
        uffs.append(folder / f"test_{cfg or 'base'}.uff")
        write_uff(uffs[-1], test)
    return board, uffs, data


def judge_holdout(case, truth: dict, data: dict) -> list:
    """:func:`test_diagnose_bench.judge`, except that noise-only data need not be called noise (the
    codes' own difference may exceed the stated noise), only left without effects."""
    bad = judge(case, truth, data)
    return [b for b in bad if not b.startswith("noise_only is")] if case.noise_only else bad


#: hold-out cases diagnose misses today, and why (``benchmarks/bench_diagnose.py`` reports a pass of one
#: as a change to take note of)
KNOWN: dict = {
    "ho_rib_card": "rib found as two parallel ribs beside it (x = 115.6 mm, EI 0.48 N m^2, and x = 97.9 mm, EI 0.35, "
                   "for one at x = 110 mm, EI 0.8: their sum within 4 %); 0.61 % after. Found as one (x = 110.3 mm, "
                   "EI 0.92) with 0.40 % after while the search tried pieces of lines without the whole line beside "
                   "each: the margin is thin either way",
    "ho_transducer_cfg": "transducer found in place (3 mm) and size (-19 %); 1.16 % after: the configurations' large "
                         "bodies with rotary inertia are attached differently in the two codes (1.08 % with no "
                         "effect, ho_noise_card_cfg)",
}


def cases():
    """The cases of :data:`holdout_cases.IN_SUITE` (:data:`KNOWN` misses are
    ``benchmarks/bench_diagnose.py``'s to follow)."""
    return [pytest.param(hc.BY_NAME[n], id=n, marks=[pytest.mark.xdist_group(n)]) for n in hc.IN_SUITE]


@pytest.mark.slow
@pytest.mark.parametrize("case", cases())
def test_diagnose_holdout(case, tmp_path):
    board, uffs, truth = make_holdout(case, tmp_path / "case")
    data = run_diagnose(case, board, uffs, tmp_path)
    print(json.dumps({k: data.get(k) for k in ("effects", "noise_only", "before", "parameters_only", "after")}, indent=1))
    bad = judge_holdout(case, truth, data)
    assert not bad, f"{case.name}: " + "; ".join(bad)
