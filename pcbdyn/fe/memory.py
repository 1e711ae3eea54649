"""Where the large arrays of a solve get their memory pages.

The command line calls both functions here before any work (``bench_modal.py`` too, as it runs
as the command line does).

numpy asks the kernel for transparent huge pages on every array of 4 MB and more (``madvise``).
Where the kernel's policy is to compact memory on such a fault (``defrag = madvise``, this machine's
setting), a fresh process pays for the compaction the first time it touches its matrices, factor
and Lanczos basis: the 112k-DOF plate (``bench_modal.py --sizes 136 --support simple``, three fresh
processes each, alternated) took 2.49-2.73 s (median 2.56 s) without the advice against 2.84-3.07 s
(median 2.94 s) with it; the 1M-DOF plate 31.1 against 30.8 s (no change). So the command line
turns the advice off and leaves huge pages to the kernel's own policy (``NUMPY_MADVISE_HUGEPAGE=1``
keeps numpy's).

glibc gives every block of 128 kB and more (32 MB once it has seen such blocks freed) its own
``mmap`` and returns it to the kernel when freed, and returns freed memory at the top of its heap
too: each of a solve's many large temporaries (element matrices by chunk, gather masks, CSR value
arrays, Lanczos blocks) then costs fresh zeroed pages, a fault per 4 kB. :func:`reuse_freed_memory`
keeps freed memory in the process for the next arrays: the 112k-DOF plate 2.29-2.77 s against
1.97-2.07 s (fresh processes alternated, three each), peak memory the same (588 MB); the 1M-DOF
plate 28.7 -> 25.0 s, peak 4.92 -> 4.98 GB (tilted: 46.8 s, 6.75 GB).
"""

from __future__ import annotations

import ctypes
import os

import numpy as np

#: glibc's mallopt parameters
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_LARGEST = 2**31 - 1


def plain_pages() -> None:
    """Stop numpy advising huge pages for the rest of this process (and the workers forked from
    it), unless ``NUMPY_MADVISE_HUGEPAGE`` chooses; a no-op where numpy has no such switch."""
    if os.environ.get("NUMPY_MADVISE_HUGEPAGE", "").strip():
        return
    core = getattr(np, "_core", None) or getattr(np, "core", None)
    setter = getattr(getattr(core, "multiarray", None), "_set_madvise_hugepage", None)
    if setter is not None:
        setter(False)


def reuse_freed_memory() -> None:
    """Let glibc keep freed memory for reuse in this process (and the workers forked from it): no
    ``mmap`` of its own for a large block, no trimming of the heap; the process's memory then stays
    at its peak until it ends. A no-op off glibc, or where ``MALLOC_MMAP_THRESHOLD_``,
    ``MALLOC_TRIM_THRESHOLD_`` or ``GLIBC_TUNABLES`` chooses."""
    if any(os.environ.get(v, "").strip() for v in ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_", "GLIBC_TUNABLES")):
        return
    try:
        libc = ctypes.CDLL(None)
    except OSError:
        return
    if hasattr(libc, "gnu_get_libc_version") and hasattr(libc, "mallopt"):
        libc.mallopt(_M_MMAP_THRESHOLD, _LARGEST)
        libc.mallopt(_M_TRIM_THRESHOLD, _LARGEST)
