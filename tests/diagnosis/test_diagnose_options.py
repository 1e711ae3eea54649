"""``pcbdyn diagnose --quick``, ``--workers`` and ``--scheduler`` (issue 26) on a bench case (a standoff
under the free card, :mod:`bench_cases`): a first look finds what the full run finds, and trial fits run
in this process, in worker processes or on a Dask cluster give the same findings to rounding."""

from __future__ import annotations

import json
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_cases as bc  # noqa: E402
from test_diagnose_bench import judge, location_error_mm  # noqa: E402

from pcbdyn.cli import main  # noqa: E402

#: the module's fixtures are made once: its tests run on one xdist worker
pytestmark = pytest.mark.xdist_group("diagnose_options")

CASE = bc.BY_NAME["gs_standoff"]
#: the kinds searched (the standoff's and the one a point residual is most often mistaken for)
KINDS = "ground_spring,point_mass"


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    return bc.make_case(CASE, tmp_path_factory.mktemp("options"))


def _diagnose(case, out: Path, *extra) -> tuple:
    board, uffs, truth = case
    js = out / "d.json"
    args = ["diagnose", str(board), *bc.cli_tests(CASE, uffs), "--noise", f"f={CASE.noise[0]:g},shape={CASE.noise[1]:g}",
            "--kinds", KINDS, "--json", str(js), "--out", str(out / "o"), *extra]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    return json.loads(js.read_text()), r.output


@pytest.fixture(scope="module")
def default_run(case, tmp_path_factory):
    """(JSON, progress) of the run with the default workers (the cores)."""
    data, output = _diagnose(case, tmp_path_factory.mktemp("default"))
    assert not judge(CASE, case[2], data)
    return data, output


@pytest.fixture(scope="module")
def default(default_run):
    return default_run[0]


def _same_findings(a: dict, b: dict, mag_rel: float, at_mm: float) -> None:
    assert [e["type"] for e in a["effects"]] == [e["type"] for e in b["effects"]]
    for x, y in zip(a["effects"], b["effects"]):
        assert location_error_mm(x, {"at_mm": y["at_mm"]}) <= at_mm
        assert x["magnitude"] == pytest.approx(y["magnitude"], rel=mag_rel)


def test_quick_finds_what_the_full_run_finds(case, default, tmp_path):
    """The first look: the standoff within the bench's tolerances (type, 15 mm, 30 %, after < 0.5 %),
    at the full run's place within one model element and its stiffness within 10 %; the progress
    names the one finer mesh level it measured."""
    data, output = _diagnose(case, tmp_path, "--quick", "--html")
    assert not judge(CASE, case[2], data)
    _same_findings(data, default, 0.10, 1e3 * bc.MODEL_MESH)
    assert "level 1 of 1" in output and "level 2 of" not in output
    assert data["statistics"]["quick"] and not default["statistics"]["quick"]
    # where its time went: the steps it ran, each within the run (their sum no more than the run's wall time)
    stages = data["statistics"]["stage_seconds"]
    assert {"models", "error budget", "parameters", "search"} <= stages.keys()
    assert min(stages.values()) >= 0.0
    assert sum(stages.values()) <= float(re.search(r"done in ([\d.]+) s", output).group(1)) + 0.1
    # the page shows the effects found on the modes of the model that declares them (issue 44)
    page = (tmp_path / "o" / "report.html").read_text()
    assert 'data-title="Effects found"' in page and "Effects found, on the modes of the model" in page
    view = json.loads(re.search(r'class="view-data">(.*?)</script>', page, re.S).group(1))
    drawn = [o for o in view["scenes"][0]["outlines"] if o["kind"] == "effect"]
    assert [o["label"].split()[0] for o in drawn] == [e["type"] for e in data["effects"]]
    for o, e in zip(drawn, data["effects"]):
        assert np.asarray(o["xyz"])[0, :2] == pytest.approx(e["at_mm"], abs=1e-3)
    assert view["scenes"][0]["title"].endswith("with the effects") and len(view["labels"]) >= 1


def test_scheduler_gives_the_same_findings(case, default, tmp_path):
    """Trial fits on a Dask cluster (in this process): the default run's findings to rounding."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cl:
        data, output = _diagnose(case, tmp_path, "--scheduler", cl.scheduler_address)
    assert "trial fits" in output
    _same_findings(data, default, 1e-6, 1e-3)
    assert data["after"]["max_freq_error_pct"] == pytest.approx(default["after"]["max_freq_error_pct"], rel=1e-6)
    assert np.isfinite(data["effects"][0]["uncertainty"])


def test_worker_processes_give_the_findings_of_one_process(case, default_run, tmp_path):
    """The quick fits that screen each scan and the full trial fits run in two local worker processes
    by default and all in this process with ``--workers 1``, and ``pcbdyn update``'s fit of the declared
    parameters on a spare core beside the diagnosis's own (with two cores or more) or after it: the same
    findings and the same update (to round-off), so where a job ran never changes an answer."""
    default, beside = default_run
    data, output = _diagnose(case, tmp_path, "--workers", "1")
    assert "as pcbdyn update does" in output and "on a spare core" not in output
    if (os.cpu_count() or 1) > 1:
        assert "as pcbdyn update does, on a spare core" in beside
    ran, ran_beside = data["statistics"]["update"], default["statistics"]["update"]
    assert ran["status"] == ran_beside["status"] and list(ran["parameters"]) == list(ran_beside["parameters"])
    assert list(ran["parameters"].values()) == pytest.approx(list(ran_beside["parameters"].values()), rel=1e-9)
    assert "trials screened on the reanalysis" in output
    _same_findings(data, default, 1e-9, 1e-6)
    assert data["after"]["max_freq_error_pct"] == pytest.approx(default["after"]["max_freq_error_pct"], rel=1e-9)
