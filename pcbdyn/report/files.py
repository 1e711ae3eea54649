"""Text and JSON results, written atomically (see :mod:`pcbdyn.atomic`)."""

from __future__ import annotations

import json

from ..atomic import atomic_path

__all__ = ["atomic_path", "write_text", "write_json"]


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def write_json(path, data) -> None:
    write_text(path, json.dumps(data, indent=2) + "\n")
