"""Shared paths and helpers for the board tests."""

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = Path("/work/shared/reference")
EXAMPLES = ROOT / "examples"
DATA = Path(__file__).resolve().parent / "data"


def thesis_case(name):
    return json.loads((REFERENCE / "thesis_tables.json").read_text())["cases"][name]


def write_board(tmp_path, text, name="board.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def rel_err(a, b):
    import numpy as np

    return np.asarray(a) / np.asarray(b) - 1.0
