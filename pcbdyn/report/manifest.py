"""A run's output folder holds only that run's files, and is replaced whole.

A run that writes into a folder (``--out``) fills a new folder beside it (:func:`replacing`); when it has
written everything, the new folder records its files in ``pcbdyn-manifest.json`` (relative paths and a
SHA-256 of each), receives the files of the earlier folder that are not an earlier run's output, and
takes the earlier folder's place in one step. An interrupt before then (Ctrl-C while pictures are drawn,
an error, a killed run) leaves the earlier folder as it was, its manifest matching its files. The earlier
run's files this run did not write again are gone with the earlier folder; a file the earlier manifest
does not list (the user's), or one changed since pcbdyn wrote it (its hash differs), is carried over,
unless this run wrote a file of that name. A folder that is not pcbdyn's (it holds files but no manifest), or
the current folder (or one above it), is not replaced (:func:`unreplaceable`).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from contextlib import contextmanager
from pathlib import Path

from ..atomic import LOCK_FILE, MARK, replaced_folder
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


def unreplaceable(out) -> str | None:
    """Why a run cannot replace the folder ``out`` whole (None when it can): it is the current folder or
    one above it, or it holds files but no manifest (a folder of the user's, not a run's output)."""
    out = Path(out).resolve()
    if Path.cwd().resolve().is_relative_to(out):
        return "is the current folder (or holds it); give a folder of its own, e.g. --out results"
    if out.is_dir() and not (out / MANIFEST).is_file() and any(out.iterdir()):
        return (f"holds files but no {MANIFEST}: it is not an output folder of pcbdyn, whose runs replace "
                "their folder whole; give a new or empty folder")
    return None


class Staged:
    """The folder a run writes into (``path``) in place of ``out``; ``removed``, once the run is in place:
    the earlier run's files it did not write again."""

    def __init__(self, out: Path, path: Path):
        self.out, self.path, self.removed = out, path, []

    def final(self, path) -> Path:
        """Where ``path`` (written under :attr:`path`) is once the run is in place."""
        return self.out / Path(path).relative_to(self.path)


def _carry_over(out: Path, new: Path) -> list:
    """Link (else copy) into ``new`` the files of ``out`` that are not the earlier run's unchanged output and
    that ``new`` does not hold; returns the earlier run's files left behind (relative paths)."""
    if not out.is_dir():
        return []
    earlier, removed = _earlier(out), []
    for p in sorted(out.rglob("*")):
        rel = p.relative_to(out).as_posix()
        dest = new / rel
        if rel == MANIFEST or MARK in p.name or (p.is_dir() and not p.is_symlink() and any(p.iterdir())):
            continue
        if earlier.get(rel) is not None and p.is_file() and not p.is_symlink() and _digest(p) == earlier[rel]:
            removed += [] if dest.exists() else [rel]
        elif p.is_dir() and not p.is_symlink():
            dest.mkdir(parents=True, exist_ok=True)  # the user's empty folder
        elif not dest.exists():
            dest.parent.mkdir(parents=True, exist_ok=True)
            try:
                os.link(p, dest, follow_symlinks=False)
            except OSError:
                shutil.copy2(p, dest, follow_symlinks=False)
    return removed


@contextmanager
def replacing(out, command: str):
    """Yield a :class:`Staged` whose ``path`` the run writes its files into; when the block ends without
    an error that folder gets its manifest and the user's files of ``out`` and replaces ``out`` whole
    (:func:`pcbdyn.atomic.replaced_folder`); on an error ``out`` is left as it was."""
    out = Path(out)
    with replaced_folder(out) as path:
        run = Staged(out, path)
        yield run
        mine = {p.relative_to(path).as_posix(): _digest(p) for p in sorted(path.rglob("*"))
                if p.is_file() and p.relative_to(path).as_posix() != LOCK_FILE}
        run.removed = _carry_over(out, path)
        write_json(path / MANIFEST, {"written_by": command, "files": mine})
