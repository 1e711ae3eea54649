"""A run's output folder holds only that run's files.

Each run that writes into a folder records the files it wrote in ``pcbdyn-manifest.json`` there
(relative paths and a SHA-256 of each). The next run into the same folder deletes the files the
earlier manifest lists that it did not write again (a smaller rerun: fewer modes, fewer
configurations, no pictures), so no stale result sits beside the new ones. Only files pcbdyn wrote
are touched: a file not in the manifest (the user's) is never removed, nor one changed since pcbdyn
wrote it (its hash differs), nor anything outside the folder.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from .files import write_json

MANIFEST = "pcbdyn-manifest.json"


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _earlier(folder: Path) -> dict:
    """{relative path: sha256} of the earlier run's manifest ({} when there is none or it is unreadable)."""
    try:
        files = json.loads((folder / MANIFEST).read_text()).get("files", {})
    except (OSError, ValueError, AttributeError):
        return {}
    return files if isinstance(files, dict) else {}


def _inside(folder: Path, rel: str) -> Path | None:
    p = Path(rel)
    if p.is_absolute() or ".." in p.parts or not p.parts:
        return None
    return folder / p


def settle(folder, written, command: str) -> list:
    """Record ``written`` (paths inside ``folder``) as this run's files and delete the earlier
    run's files that were not written again; returns the relative paths deleted."""
    folder = Path(folder)
    root = folder.resolve()
    mine = {}
    for p in written:
        p = Path(p).resolve()
        if p.is_file() and p.is_relative_to(root):
            mine[p.relative_to(root).as_posix()] = _digest(p)
    removed = []
    for rel, digest in sorted(_earlier(folder).items()):
        p = _inside(folder, rel)
        if rel in mine or p is None or not p.is_file() or _digest(p) != digest:
            continue
        p.unlink()
        removed.append(rel)
        parent = p.parent
        while parent != folder and parent.is_dir() and not any(parent.iterdir()):
            parent.rmdir()
            parent = parent.parent
    write_json(folder / MANIFEST, {"written_by": command, "files": dict(sorted(mine.items()))})
    return removed
