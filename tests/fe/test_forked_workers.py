"""Local worker processes after this process has factorised with CHOLMOD (pcbdyn.parallel,
pcbdyn.fe.threads): GNU OpenMP's idle threads do not survive a fork, and a forked worker waited for
them forever at its first factorisation. pcbdyn caps OpenMP at one thread when imported, so that
forking is safe; where a user chose more OpenMP threads, the workers start from a fork server, and
what they share (here with a closure, as a built model holds) goes to them by cloudpickle. The spare
processes of ``spare_cores`` serve only the process that made them."""

import os
import subprocess
import sys

import pytest

SCRIPT = """
import numpy as np
import scipy.sparse as sp

import pcbdyn  # caps OpenMP before CHOLMOD loads it (unless OMP_NUM_THREADS says otherwise)
from pcbdyn.fe.linsolve import factorize
from pcbdyn.fe.threads import openmp_capped
from pcbdyn.parallel import run_jobs


def job(i, shared):
    A, unit = shared  # unit: a closure, as built models hold (plain pickle cannot send it)
    return unit(float(factorize(A).solve(np.ones(A.shape[0]))[i]))


if __name__ == "__main__":
    n = 200_000
    T = sp.diags([np.full(n - 1, -1.0), np.full(n, 4.0), np.full(n - 1, -1.0)], [-1, 0, 1])
    A = (sp.kron(sp.eye(3), T) + sp.eye(3 * n)).tocsc()
    x = factorize(A).solve(np.ones(A.shape[0]))  # the parent's CHOLMOD (and OpenMP) first
    scale = 1.0
    out = dict(run_jobs(job, [(i,) for i in range(4)], (A, lambda v: scale * v), workers=2))
    print(openmp_capped(), max(abs(out[(i,)] - x[i]) for i in range(4)))
"""


@pytest.mark.parametrize("omp_threads,capped", [(None, True), ("2", False)])
def test_workers_after_a_factorisation_finish_with_the_parent_s_answer(tmp_path, omp_threads, capped):
    """Four jobs on two workers after the parent factorised: they finish (within 120 s; each takes
    well under one) with the parent's solution, forked where OpenMP is capped, else from a server."""
    script = tmp_path / "workers.py"
    script.write_text(SCRIPT)
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_THREAD_LIMIT", "OMP_NUM_THREADS", "PCBDYN_BLAS_THREADS")}
    if omp_threads:
        env["OMP_NUM_THREADS"] = omp_threads
    try:
        run = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail("the worker processes hung")
    assert run.returncode == 0, run.stderr
    was_capped, error = run.stdout.split()
    assert was_capped == str(capped)
    assert float(error) < 1e-12


def _spare_in_job(i, shared):
    from pcbdyn.parallel import spare

    return spare()


def test_spare_cores_serve_only_the_process_that_made_them():
    """Within ``spare_cores(2)`` this process has one spare process, whose jobs run elsewhere (another
    pid) and return their value; a worker forked by ``run_jobs`` meanwhile has none (it would wait on
    a pool it does not own); after the block, none is left."""
    from pcbdyn.parallel import beside, run_jobs, spare, spare_cores

    with spare_cores(2):
        assert spare() == 1
        assert beside(os.getpid).result() != os.getpid()
        assert beside(pow, 3, 4).result() == 81
        assert dict(run_jobs(_spare_in_job, [(0,), (1,)], None, workers=2)) == {(0,): 0, (1,): 0}
    assert spare() == 0
    with spare_cores(1):
        assert spare() == 0
