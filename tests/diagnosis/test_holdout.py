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
from test_diagnose_bench import judge, match, run_diagnose  # noqa: E402

from pcbdyn.board.entries import RibSection  # noqa: E402
from pcbdyn.diagnosis import geometry_fit  # noqa: E402

SECTION = RibSection()


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
    "ho_transducer_cfg": "transducer found in place (3 mm) and size (-19 %); 1.16 % after: the configurations' large "
                         "bodies with rotary inertia are attached differently in the two codes (1.08 % with no "
                         "effect, ho_noise_card_cfg)",
}


def cases():
    """The cases of :data:`holdout_cases.IN_SUITE` (:data:`KNOWN` misses are
    ``benchmarks/bench_diagnose.py``'s to follow)."""
    return [pytest.param(hc.BY_NAME[n], id=n, marks=[pytest.mark.xdist_group(n)]) for n in hc.IN_SUITE]


def _bar_with_its_mass(data: dict, truth: dict) -> None:
    """The bar (10 x 4 mm aluminium, :class:`RibSection`'s section: 17.5 g over the card's 162 mm) found
    as a stiffener whose section, as fitted, carries its mass (``mass_kg``, with any mass found beside
    it, within 30 %), on its line: the line (the mean of its ends) within the shortest step of
    :mod:`pcbdyn.diagnosis.geometry_fit`'s move across it (0.42 mm on the model's 6.75 mm elements;
    embedded in them, before the card was meshed along it, it stayed 0.7 mm off), each end within two
    (where an end stops within a step hangs on the machine's round-off: the same code ended -0.12 and
    +0.48 mm off on one machine, within 0.42 mm on another)."""
    (t,) = truth["effects"]
    e, _ = match(data["effects"], t)
    found = e["mass_kg"] + sum(x["magnitude"] for x in data["effects"] if x["type"] in ("point_mass", "line_mass"))
    true = SECTION.rho * (12.0 * t["magnitude"] / (SECTION.E * SECTION.h**3)) * SECTION.h * 0.162
    assert true == pytest.approx(17.5e-3, rel=0.01) and found == pytest.approx(true, rel=0.30)
    resolution = 1e3 * bc.MODEL_MESH * geometry_fit.MOVES["across"] * geometry_fit.STEP_RANGE[0]
    off = np.array([end[1] - t["at_mm"][1] for end in e["path_mm"]])
    assert resolution < 0.7 and abs(off.mean()) <= resolution and np.abs(off).max() <= 2 * resolution, e
    assert data["parameters_only"]["max_freq_error_pct"] > 2.0


def _bracket_on_its_spring(data: dict, truth: dict) -> None:
    """The bracket's spring placed between nodes from the bounce's rigid-body part to within a
    millimetre (the model's nodes are 6.75 mm apart): the card's bounce on the spring (test mode 1) has
    no partner among the free model's elastic modes before, is reported as the support's evidence, and
    is paired after; the bracket takes the error below what the parameters alone leave, which the noise
    cannot give."""
    spring = next(t for t in truth["effects"] if t["type"] == "ground_spring")
    assert match(data["effects"], spring)[1] <= 1.0
    assert data["statistics"]["p_value_noise"] < data["statistics"]["alpha"]
    assert data["after"]["max_freq_error_pct"] < data["parameters_only"]["max_freq_error_pct"]
    assert data["statistics"]["support_test_modes"] == {"base": [1]}
    before, after = (data[k]["configurations"][0] for k in ("before", "after"))
    assert before["unpaired_test_modes"] == [1] and not after.get("unpaired_test_modes")


#: what a hold-out case must show beyond :func:`judge_holdout` (what the bench's compound cases,
#: :data:`bench_cases.CASES` ``compound_*``, asked of data pcbdyn made, asked here of another code's)
SHOWS = {"ho_al_bar": _bar_with_its_mass, "ho_bracket": _bracket_on_its_spring}


@pytest.mark.slow
@pytest.mark.parametrize("case", cases())
def test_diagnose_holdout(case, tmp_path):
    board, uffs, truth = make_holdout(case, tmp_path / "case")
    data = run_diagnose(case, board, uffs, tmp_path)
    print(json.dumps({k: data.get(k) for k in ("effects", "noise_only", "before", "parameters_only", "after")}, indent=1))
    bad = judge_holdout(case, truth, data)
    assert not bad, f"{case.name}: " + "; ".join(bad)
    if case.name in SHOWS:
        SHOWS[case.name](data, truth)
