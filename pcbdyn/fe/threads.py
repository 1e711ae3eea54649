"""How many threads the BLAS and OpenMP pools may use while pcbdyn computes.

OpenBLAS starts as many threads as cores. On the 2-core machines pcbdyn runs on, its two threads
made the modal solves 1.4-4x slower than one (they fight over small dense kernels and over cores
other work is using): a ``pcbdyn diagnose`` run spent 121 s of CPU instead of 48 s for the same
result. So the eigen-solutions run under a limit, and the command line sets it for the whole run.

The limit is ``PCBDYN_BLAS_THREADS`` when set (0: leave the libraries alone); otherwise, when the
environment already says how many threads BLAS may use (``OPENBLAS_NUM_THREADS``,
``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``), that choice is kept; otherwise 1.
"""

from __future__ import annotations

import contextlib
import os

ENV = "PCBDYN_BLAS_THREADS"
_LIBRARY_ENV = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
_controller = None


def thread_limit() -> int | None:
    """The BLAS/OpenMP thread limit pcbdyn applies, or None to apply none (see the module doc)."""
    value = os.environ.get(ENV, "").strip()
    if value:
        try:
            n = int(value)
        except ValueError:
            raise ValueError(f"{ENV} must be a whole number of threads (0: no limit), got '{value}'") from None
        return n if n > 0 else None
    if any(os.environ.get(name) for name in _LIBRARY_ENV):
        return None
    return 1


def limited():
    """A context manager that holds the BLAS/OpenMP pools to :func:`thread_limit` threads (a no-op
    when there is no limit). The controller lists the loaded libraries once (~1 ms); each entry
    then costs ~20 us, so it can wrap every small solve."""
    n = thread_limit()
    return contextlib.nullcontext() if n is None else _limit(n)


def _limit(n: int):
    global _controller
    if _controller is None:
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()
    return _controller.limit(limits=n)


def limit_process() -> None:
    """Apply :func:`thread_limit` to this process for good (the limiter is simply never undone),
    and pass it on to child processes through the environment, since worker pools start their
    own BLAS. For entry points (the CLI)."""
    n = thread_limit()
    if n is None:
        return
    _limit(n)
    for name in _LIBRARY_ENV[:2]:
        os.environ.setdefault(name, str(n))
