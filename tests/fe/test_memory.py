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
