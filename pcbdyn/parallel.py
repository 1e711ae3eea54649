"""Running independent jobs (the shots of a study, the candidates of a diagnosis scan) in this process,
in local worker processes, or on a Dask cluster when a scheduler address is given; and, within
:func:`spare_cores`, single jobs beside this process's own work (:func:`beside`).

Each job is ``fn(*args, shared)``: ``shared`` (a case, a residual) is sent to every worker once (the
process pool's initializer, Dask's scatter), the arguments per job. Results come back as they finish;
callers that need an order sort them, and jobs are seeded by their own arguments, so the results do not
depend on where they ran. Local workers are forked, inheriting this process's built models and caches,
where that is safe (:func:`pcbdyn.fe.threads.openmp_capped`); otherwise they start from a fork server
and ``shared`` goes to them by cloudpickle (as to Dask), which also carries closures plain pickle cannot.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager

from .fe.threads import openmp_capped

_SHARED = None
#: the process pool of :func:`spare_cores` and the process that made it: (pid, size, pool or None)
_SPARE = None


class _Pickled:
    """``shared`` on its way to workers started from a fork server."""

    def __init__(self, obj):
        import cloudpickle

        self.blob = cloudpickle.dumps(obj)

    def load(self):
        import cloudpickle

        return cloudpickle.loads(self.blob)


def _context():
    """How worker processes start: forked where OpenMP is capped at one thread (forking is safe
    then, :func:`pcbdyn.fe.threads.openmp_capped`), else from a fork server."""
    return multiprocessing.get_context("fork" if openmp_capped() else "forkserver")


def _init(shared) -> None:
    global _SHARED
    _SHARED = shared.load() if isinstance(shared, _Pickled) else shared


def _call(fn, args):
    return fn(*args, _SHARED)


def run_jobs(fn, jobs, shared, workers: int | None = None, scheduler: str | None = None, done=None):
    """Yield ``(args, fn(*args, shared))`` for every ``args`` of ``jobs``, as they finish. ``scheduler``: a
    Dask scheduler address ("tcp://host:8786"), or a ``distributed.Client``; otherwise ``workers`` local
    processes (default: the cores; 1: in this process). ``done(args)`` is called after each job."""
    jobs = list(jobs)
    if scheduler is not None:
        yield from _on_dask(fn, jobs, shared, scheduler, done)
        return
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    if workers <= 1 or len(jobs) <= 1:
        for args in jobs:
            out = fn(*args, shared)
            if done:
                done(args)
            yield args, out
        return
    fork = openmp_capped()
    with ProcessPoolExecutor(min(workers, len(jobs)), _context(), initializer=_init,
                             initargs=(shared if fork else _Pickled(shared),)) as pool:
        futures = {pool.submit(_call, fn, args): args for args in jobs}
        for fut in as_completed(futures):
            if done:
                done(futures[fut])
            yield futures[fut], fut.result()


def _on_dask(fn, jobs, shared, scheduler, done):
    try:
        from distributed import Client, as_completed as dask_completed
    except ImportError:  # pragma: no cover - a dependency of pcbdyn
        raise RuntimeError("--scheduler needs the dask[distributed] package") from None
    client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
    try:
        remote = client.scatter(shared, broadcast=True)
        futures = {client.submit(fn, *args, remote, pure=False): args for args in jobs}
        for fut in dask_completed(futures):
            if done:
                done(futures[fut])
            yield futures[fut], fut.result()
    finally:
        if client is not scheduler:
            client.close()


@contextmanager
def spare_cores(workers: int | None = None):
    """Within this block, :func:`beside` runs jobs on ``workers - 1`` more local processes (None: the
    cores), started when first needed and stopped at its end. Made for work this process would
    otherwise do one piece after another on one core while the others idle (the configurations of a
    re-solve); only this process uses them, never a worker forked from it."""
    global _SPARE
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    outer, _SPARE = _SPARE, (os.getpid(), max(workers - 1, 0), None)
    try:
        yield
    finally:
        pool, _SPARE = _SPARE[2], outer
        if pool is not None:
            pool.shutdown(cancel_futures=True)


def spare() -> int:
    """How many processes :func:`beside` has for this process now (0 outside :func:`spare_cores`)."""
    return _SPARE[1] if _SPARE is not None and _SPARE[0] == os.getpid() else 0


def beside(fn, *args):
    """A future of ``fn(*args)`` run on a spare process (see :func:`spare`, which must be > 0); the
    arguments go by pickle."""
    global _SPARE
    pid, n, pool = _SPARE
    if pool is None:
        pool = ProcessPoolExecutor(n, _context())
        _SPARE = (pid, n, pool)
    return pool.submit(fn, *args)
