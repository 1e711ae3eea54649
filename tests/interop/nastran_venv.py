"""The pyNastran side of the export tests: run nastran_dump.py in the .venv-nastran virtual
environment that scripts/setup.sh makes (pyNastran 1.4.1 needs numpy<2) and return its JSON."""

import json
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PYTHON = ROOT / ".venv-nastran" / "bin" / "python"
DUMP = Path(__file__).with_name("nastran_dump.py")


def read_deck(path) -> dict:
    """pyNastran's reading of the deck at ``path`` (skips the test when its venv is absent)."""
    if not PYTHON.exists():
        pytest.skip(f"{PYTHON} is absent: run scripts/setup.sh (it makes .venv-nastran with pyNastran and numpy<2)")
    run = subprocess.run([str(PYTHON), str(DUMP), str(path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"pyNastran could not read {path}:\n{run.stderr[-3000:]}"
    return json.loads(run.stdout)
