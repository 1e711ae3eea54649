"""How many threads the BLAS and OpenMP pools may use while pcbdyn computes.

OpenBLAS and OpenMP start as many threads as cores, and numpy, SciPy and CHOLMOD each load their
own OpenBLAS. On the 2-core machines pcbdyn runs on, those threads made the modal solves 1.4-8x
slower than one thread each (they spin waiting for each other and for cores other work is
using): a ``pcbdyn diagnose`` run spent 121 s of CPU instead of 48 s for the same result, and
repeated solves of the six-part card took 1149 ms instead of 141 ms each at load 5. So the
eigen-solutions run under a limit, and the command line sets it for the whole run.

The limit is ``PCBDYN_BLAS_THREADS`` for both pools when set (0: leave them alone). Otherwise
each pool whose own variable is already in the environment keeps that choice (BLAS:
``OPENBLAS_NUM_THREADS``, ``MKL_NUM_THREADS``; OpenMP: ``OMP_NUM_THREADS``) and the others get 1.

One OpenMP thread is also a cap set before the runtime loads (:func:`cap_openmp`, when pcbdyn is
imported): CHOLMOD's supernodal loops ask for their own number of threads, past any limit set
through the API, and cost more than they save (the 112k-DOF plate solved in 1.8 s instead of
2.3-2.6 s with the cap, quiet 2-core machine); and GNU OpenMP's idle threads make a forked worker
process wait forever at its first parallel loop (:func:`openmp_capped` tells when forking is safe).
"""

from __future__ import annotations

import contextlib
import ctypes
import os

ENV = "PCBDYN_BLAS_THREADS"
#: the environment variables that already choose each pool's threads
_POOL_ENV = {"blas": ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"), "openmp": ("OMP_NUM_THREADS",)}
_controller = None


def thread_limit() -> dict:
    """{pool: threads} for the pools pcbdyn limits ("blas", "openmp"); empty for none (see the
    module doc)."""
    value = os.environ.get(ENV, "").strip()
    if value:
        try:
            n = int(value)
        except ValueError:
            raise ValueError(f"{ENV} must be a whole number of threads (0: no limit), got '{value}'") from None
        return {pool: n for pool in _POOL_ENV} if n > 0 else {}
    return {pool: 1 for pool, names in _POOL_ENV.items() if not any(os.environ.get(v) for v in names)}


def limited():
    """A context manager that holds the thread pools to :func:`thread_limit` (a no-op when there
    is none). The controller lists the loaded libraries once (~1 ms); each entry then costs
    ~20 us, so it can wrap every small solve."""
    limits = thread_limit()
    return _limit(limits) if limits else contextlib.nullcontext()


def _limit(limits: dict):
    global _controller
    if _controller is None:
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()
    return _controller.limit(limits=limits)


def limit_process() -> None:
    """Apply :func:`thread_limit` to this process for good (the limiter is simply never undone),
    and pass it on to child processes through the environment, since worker pools start their
    own libraries. For entry points (the CLI)."""
    limits = thread_limit()
    if not limits:
        return
    _limit(limits)
    for pool, n in limits.items():
        os.environ.setdefault(_POOL_ENV[pool][0], str(n))


def cap_openmp() -> None:
    """Cap the OpenMP runtimes loaded from now on at one thread (``OMP_THREAD_LIMIT``) when pcbdyn's
    OpenMP limit is one thread (:func:`thread_limit`, or ``OMP_NUM_THREADS=1``) and no cap is set.
    Must run before gmsh or CHOLMOD load the runtime: :mod:`pcbdyn` calls it when imported."""
    if thread_limit().get("openmp") == 1 or os.environ.get("OMP_NUM_THREADS", "").strip() == "1":
        os.environ.setdefault("OMP_THREAD_LIMIT", "1")


def openmp_capped() -> bool:
    """True when no OpenMP runtime loaded in this process may run more than one thread (none loaded,
    or each capped at one): only then can it fork workers that use OpenMP (CHOLMOD, gmsh)."""
    from threadpoolctl import threadpool_info

    for info in threadpool_info():
        if info["user_api"] == "openmp":
            try:
                if ctypes.CDLL(info["filepath"]).omp_get_thread_limit() != 1:
                    return False
            except (OSError, AttributeError):
                return False
    return True
