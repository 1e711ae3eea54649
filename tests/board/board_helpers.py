"""Shared paths and helpers for the board tests."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
DATA = Path(__file__).resolve().parent / "data"


from data_files import write_board  # noqa: E402,F401  (re-exported for the board tests)
from reference import thesis_case  # noqa: E402,F401  (re-exported for the board tests)


def rel_err(a, b):
    import numpy as np

    return np.asarray(a) / np.asarray(b) - 1.0
