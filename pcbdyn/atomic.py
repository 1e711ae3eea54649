"""Atomic file output shared by every layer: write to a temporary file in the target folder, then
rename it over the target, so an interrupted run never leaves a half-written or lost file."""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path``; on success it replaces ``path`` with the usual
    permissions of a new file (mkstemp's private 0600 is widened to 0666 less the umask)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_checked(path, text: str, load, error=ValueError) -> Path:
    """Write ``text`` to ``path`` atomically after ``load(temporary file)`` accepted it (the file is read
    beside its destination, so relative paths in it resolve as they will); otherwise ``error`` says
    why and nothing is written. Returns ``path``."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
        try:
            load(tmp)
        except ValueError as exc:
            raise error(f"{path.name}: the file to write does not load ({exc}); nothing was written") from None
    return path
