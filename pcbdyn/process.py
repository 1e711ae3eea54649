"""What every run of the command line sets for its whole process before any work (and a benchmark
that measures a solve as the command line runs it), without importing the commands."""

from __future__ import annotations

from .fe.memory import plain_pages, reuse_freed_memory
from .fe.threads import limit_process


def process_settings() -> None:
    """The thread limits and where large arrays get their memory, for this process and its workers."""
    limit_process()  # one BLAS and OpenMP thread unless PCBDYN_BLAS_THREADS or the environment say otherwise
    plain_pages()  # no huge-page advice on numpy's arrays (pcbdyn.fe.memory)
    reuse_freed_memory()  # and freed memory kept for the next arrays
