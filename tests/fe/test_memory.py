"""pcbdyn.fe.memory: the command line stops numpy advising huge pages (a fresh process paid the
kernel's compaction on first touch), unless NUMPY_MADVISE_HUGEPAGE chooses."""

import os
import subprocess
import sys

import pytest

SCRIPT = """
import numpy as np
from pcbdyn.fe.memory import plain_pages
core = getattr(np, "_core", None) or np.core
before = core.multiarray._get_madvise_hugepage()
plain_pages()
print(before, core.multiarray._get_madvise_hugepage())
"""


@pytest.mark.parametrize("choice,expected", [(None, "False"), ("1", "True"), ("0", "False")])
def test_plain_pages_leaves_a_stated_choice_alone(choice, expected):
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if choice is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = choice
    out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.split()[1] == expected


MMAPPED = """
import ctypes, sys
import numpy as np
from pcbdyn.fe.memory import reuse_freed_memory

class Info(ctypes.Structure):
    _fields_ = [(f, ctypes.c_size_t) for f in ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks",
                                                 "fsmblks", "uordblks", "fordblks", "keepcost")]

libc = ctypes.CDLL(None)
if not hasattr(libc, "mallinfo2"):
    print("skip"); sys.exit()
libc.mallinfo2.restype = Info
if sys.argv[1] == "reuse":
    reuse_freed_memory()
a = np.ones(8_000_000)  # 64 MB
print(libc.mallinfo2().hblkhd >= a.nbytes)
"""


@pytest.mark.parametrize("how,env,mmapped", [("reuse", {}, "False"), ("reuse", {"MALLOC_TRIM_THRESHOLD_": "131072"}, "True"),
                                             ("plain", {}, "True")])
def test_reuse_freed_memory_keeps_large_arrays_off_their_own_mmap(how, env, mmapped):
    """After reuse_freed_memory a 64 MB array comes from the heap (reused once freed), not from an
    mmap of its own that glibc would return to the kernel; a stated glibc choice is left alone."""
    base = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_") and k != "GLIBC_TUNABLES"}
    out = subprocess.run([sys.executable, "-c", MMAPPED, how], env=base | env, capture_output=True, text=True,
                         check=True).stdout.strip()
    if out == "skip":
        pytest.skip("not glibc >= 2.33 (no mallinfo2)")
    assert out == mmapped
