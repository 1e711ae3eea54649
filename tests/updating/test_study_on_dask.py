"""A study runs its shots on a Dask cluster (a LocalCluster started here) with the same results as in
local processes and in this process (issue 23: --scheduler)."""

import pytest

from pcbdyn.problems.cases import SimulatedFreePCB
from pcbdyn.updating.study import run_study

distributed = pytest.importorskip("distributed")


def test_a_study_on_a_local_dask_cluster_gives_the_local_results():
    case = SimulatedFreePCB()
    args = dict(levels=[0.5, 1.0], shots=4, methods=("tls-qrf", "svd-qr"), kinds=("qms",), seed=3, progress=False,
                batch=2)
    here = run_study(case, workers=1, **args)
    pool = run_study(case, workers=2, **args)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_dask = run_study(case, scheduler=cluster.scheduler_address, **args)
    assert len(here) == 2 * 4 * 2
    for other in (pool, on_dask):
        assert other["selected"].tolist() == here["selected"].tolist()
        assert other["success_ratio"].tolist() == here["success_ratio"].tolist()
