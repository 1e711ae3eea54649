"""The examples in the docstrings of the README's Python API path run as written (numpydoc
``Examples`` sections): a reader who copies one into a session started at the repository's root gets
what it shows. They use the bundled examples by relative path, so they run from the root."""

import doctest
import importlib
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: the modules of the README's API path, in its order: read a board, build and solve it, simulate and
#: read a test, correlate, update and write the updated board; then the MAC and the noise model
MODULES = [
    "pcbdyn.board.board",
    "pcbdyn.fe.modal",
    "pcbdyn.testdata.csvio",
    "pcbdyn.testdata.noise",
    "pcbdyn.testdata.simulate",
    "pcbdyn.testdata.uff",
    "pcbdyn.correlation.correlate",
    "pcbdyn.correlation.mac",
    "pcbdyn.problems.problem",
    "pcbdyn.problems.fit",
]


@pytest.fixture(scope="module")
def at_root():
    here = os.getcwd()
    os.chdir(ROOT)
    yield
    os.chdir(here)


def test_the_docstring_examples_run(at_root):
    """Every module of the path has an example; none fails (doctest prints the failing lines)."""
    results = {name: doctest.testmod(importlib.import_module(name),
                                     optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
               for name in MODULES}
    assert not [name for name, r in results.items() if r.attempted == 0 or r.failed]
