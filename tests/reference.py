"""The reference data (analytical and published values with their sources) the tests check
against: ``tests/data/reference`` (its README.md gives each file's sources)."""

import json
from pathlib import Path

REFERENCE_DIR = Path(__file__).resolve().parent / "data" / "reference"


def load(name: str) -> dict:
    """A reference JSON file, e.g. ``load("plates.json")``."""
    return json.loads((REFERENCE_DIR / name).read_text())


def thesis_case(name: str) -> dict:
    """One case of ``thesis_tables.json``."""
    return load("thesis_tables.json")["cases"][name]
