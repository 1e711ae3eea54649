"""The shared reference data (analytical and published values with their sources): the
``shared/reference`` folder beside the repository, as on CI, or ``$PCBDYN_REFERENCE``."""

import json
import os
from pathlib import Path

REFERENCE_DIR = Path(os.environ.get("PCBDYN_REFERENCE", Path(__file__).resolve().parents[2] / "shared" / "reference"))


def load(name: str) -> dict:
    """A reference JSON file, e.g. ``load("plates.json")``."""
    return json.loads((REFERENCE_DIR / name).read_text())


def thesis_case(name: str) -> dict:
    """One case of ``thesis_tables.json``."""
    return load("thesis_tables.json")["cases"][name]
