"""Atomic file output shared by every layer: write to a temporary file in the target folder, then
rename it over the target, so an interrupted run never leaves a half-written or lost file.

A temporary file is named ``.<stem>.pcbdyn~<random><suffix>`` beside its target and held under an
exclusive lock (flock) while it is written. A run killed mid-write (SIGKILL: no cleanup code runs)
leaves its temporary behind, but the kernel drops the lock with the process: the next atomic write
into that folder removes every such temporary whose lock it can take (:func:`clear_stale`), while
those of live writers, locked, stay. Temporary folders (:func:`temporary_folder`) work alike.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

#: marks pcbdyn's temporary files and folders (never a name a user would give)
MARK = ".pcbdyn~"
_LOCK_FILE = ".lock"


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _locked_temp(folder: Path, prefix: str, suffix: str) -> tuple:
    """(fd holding an exclusive lock, path) of a new temporary file in ``folder``; a cleaner that removed
    the file between its creation and the lock makes a new one."""
    while True:
        fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=folder)
        fcntl.flock(fd, fcntl.LOCK_EX)
        try:
            if os.stat(tmp).st_ino == os.fstat(fd).st_ino:
                return fd, Path(tmp)
        except FileNotFoundError:
            pass
        os.close(fd)


def clear_stale(folder) -> list:
    """Remove the temporary files and folders of pcbdyn in ``folder`` that no live process holds (left by
    a killed run); returns their paths."""
    removed = []
    for p in Path(folder).glob(f".*{MARK}*"):
        lock = p / _LOCK_FILE if p.is_dir() else p
        try:
            fd = os.open(lock, os.O_RDWR)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:  # held: a live writer
            os.close(fd)
            continue
        try:
            if os.stat(lock).st_ino == os.fstat(fd).st_ino:
                shutil.rmtree(p, ignore_errors=True) if p.is_dir() else p.unlink(missing_ok=True)
                removed.append(p)
        except FileNotFoundError:
            pass
        finally:
            os.close(fd)
    return removed


@contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path``; on success it replaces ``path`` with the usual
    permissions of a new file (mkstemp's private 0600 is widened to 0666 less the umask). Stale
    temporaries of killed runs in the folder are removed first (:func:`clear_stale`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    clear_stale(path.parent)
    fd, tmp = _locked_temp(path.parent, f".{path.stem}{MARK}", path.suffix)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    finally:
        os.close(fd)


@contextmanager
def temporary_folder(prefix: str = "pcbdyn"):
    """A new folder in the system's temporary folder, removed after the block; one left by a killed
    run is removed by the next use (:func:`clear_stale`)."""
    base = Path(tempfile.gettempdir())
    clear_stale(base)
    folder = Path(tempfile.mkdtemp(prefix=f".{prefix}{MARK}", dir=base))
    fd = os.open(folder / f"{_LOCK_FILE}.new", os.O_RDWR | os.O_CREAT, 0o600)
    fcntl.flock(fd, fcntl.LOCK_EX)
    os.rename(folder / f"{_LOCK_FILE}.new", folder / _LOCK_FILE)  # a cleaner sees the lock file only locked
    try:
        yield folder
    finally:
        os.close(fd)
        shutil.rmtree(folder, ignore_errors=True)


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
