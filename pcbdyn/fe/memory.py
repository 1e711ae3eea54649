"""Where the large arrays of a solve get their memory pages.

numpy asks the kernel for transparent huge pages on every array of 4 MB and more (``madvise``).
Where the kernel's policy is to compact memory on such a fault (``defrag = madvise``, this machine's
setting), a fresh process pays for the compaction the first time it touches its matrices, factor
and Lanczos basis: the 112k-DOF plate (``bench_modal.py --sizes 136 --support simple``, three fresh
processes each, alternated) took 2.49-2.73 s (median 2.56 s) without the advice against 2.84-3.07 s
(median 2.94 s) with it; the 1M-DOF plate 31.1 against 30.8 s (no change). So the command line
turns the advice off and leaves huge pages to the kernel's own policy (``NUMPY_MADVISE_HUGEPAGE=1``
keeps numpy's).
"""

from __future__ import annotations

import os

import numpy as np


def plain_pages() -> None:
    """Stop numpy advising huge pages for the rest of this process (and the workers forked from
    it), unless ``NUMPY_MADVISE_HUGEPAGE`` chooses; a no-op where numpy has no such switch."""
    if os.environ.get("NUMPY_MADVISE_HUGEPAGE", "").strip():
        return
    core = getattr(np, "_core", None) or getattr(np, "core", None)
    setter = getattr(getattr(core, "multiarray", None), "_set_madvise_hugepage", None)
    if setter is not None:
        setter(False)
