"""The shock tests share the simply supported plates of the vibration tests (tests/vibe/vibe_plates.py)
and the closed forms of closed_form.py."""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
for folder in (HERE, HERE.parent / "vibe"):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
