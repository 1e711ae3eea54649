"""Atomic file output shared by every layer: write to a temporary file in the target folder, then
rename it over the target, so an interrupted run never leaves a half-written or lost file.

A temporary file is named ``.<stem>.pcbdyn~<random><suffix>`` beside its target and held under an
exclusive lock (flock) while it is written. A run killed mid-write (SIGKILL: no cleanup code runs in
it) loses its locks with the process, and a small cleaner process started with the first temporary
(:func:`_watch`) notices the end of the run, however it ended, and removes every temporary in the
folders the run wrote to whose lock it can take (:func:`clear_stale`); those of live writers, locked,
stay. The next atomic write into a folder does the same, for runs the cleaner could not serve (a
machine reset). Temporary folders (:func:`temporary_folder`) work alike, and a folder replaced whole
(:func:`replaced_folder`) is filled as one beside it, then takes its place.
"""

from __future__ import annotations

import ctypes
import errno
import fcntl
import os
import select
import shutil
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

#: marks pcbdyn's temporary files and folders (never a name a user would give)
MARK = ".pcbdyn~"
#: the file of a temporary folder whose lock says that its run is alive
LOCK_FILE = ".lock"
#: this process's pipe to its cleaner: (pid of the process that opened it, write end, folders told)
_cleaner: list = []


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
        lock = p / LOCK_FILE if p.is_dir() else p
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


def _watch(folder: Path) -> None:
    """Have ``folder`` cleared of this run's temporaries when the run ends, even by SIGKILL: a cleaner
    process, started once per process in a session of its own (no terminal signal reaches it), reads the
    folders from a pipe whose write end only this process holds (close-on-exec: no mesher or renderer
    inherits it); the kernel closes that end with the process. At end-of-file the cleaner waits until the
    process has fully ended (its pidfd: a dying process closes the pipe before it drops its locks), then
    runs :func:`clear_stale` on each folder and exits, milliseconds after the run."""
    if not _cleaner or _cleaner[0] != os.getpid():
        read, write = os.pipe()
        actions = [(os.POSIX_SPAWN_DUP2, read, 0), (os.POSIX_SPAWN_CLOSE, read),
                   (os.POSIX_SPAWN_OPEN, 1, os.devnull, os.O_WRONLY, 0),
                   (os.POSIX_SPAWN_OPEN, 2, os.devnull, os.O_WRONLY, 0)]
        os.posix_spawn(sys.executable, [sys.executable, "-I", __file__, str(os.getpid())], dict(os.environ),
                       file_actions=actions, setsid=True)
        os.close(read)
        _cleaner[:] = [os.getpid(), write, set()]
    folder = os.fsencode(Path(folder).resolve())
    if folder not in _cleaner[2]:
        os.write(_cleaner[1], folder + b"\0")
        _cleaner[2].add(folder)


def _clean_after_writer(writer: int) -> None:
    """The cleaner's work (see :func:`_watch`): wait for the end of the process ``writer``, then clear its
    folders."""
    try:
        ended = os.pidfd_open(writer)
    except (AttributeError, OSError):  # no pidfd (not Linux), or the writer is gone already
        ended = None
    told = sys.stdin.buffer.read()
    if ended is not None:
        select.select([ended], [], [])
    while os.getppid() == writer:  # without a pidfd: the writer has ended when this process is adopted
        time.sleep(0.01)
    for folder in filter(None, set(told.split(b"\0"))):
        clear_stale(os.fsdecode(folder))


@contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path``; on success it replaces ``path`` with the usual
    permissions of a new file (mkstemp's private 0600 is widened to 0666 less the umask). Stale
    temporaries of killed runs in the folder are removed first (:func:`clear_stale`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    clear_stale(path.parent)
    _watch(path.parent)
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
def temporary_folder(prefix: str = "pcbdyn", base=None):
    """A new folder in ``base`` (default: the system's temporary folder), removed after the block; one
    left by a killed run is removed by the next use (:func:`clear_stale`)."""
    base = Path(tempfile.gettempdir() if base is None else base)
    clear_stale(base)
    _watch(base)
    folder = Path(tempfile.mkdtemp(prefix=f".{prefix}{MARK}", dir=base))
    fd = os.open(folder / f"{LOCK_FILE}.new", os.O_RDWR | os.O_CREAT, 0o600)
    fcntl.flock(fd, fcntl.LOCK_EX)
    os.rename(folder / f"{LOCK_FILE}.new", folder / LOCK_FILE)  # a cleaner sees the lock file only locked
    try:
        yield folder
    finally:
        os.close(fd)
        shutil.rmtree(folder, ignore_errors=True)


@contextmanager
def replaced_folder(target):
    """Yield a new folder beside the folder ``target`` to fill (its :data:`LOCK_FILE` aside); when the block
    ends without an error the new folder takes ``target``'s place whole, in one step where the system can
    (Linux: a rename exchange; elsewhere ``target`` moves aside just before), and ``target``'s former
    content is removed. On an error, or a killed run (:func:`clear_stale`), ``target`` stays as it was and
    the new folder goes."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    with temporary_folder(target.name, base=target.parent) as new:
        yield new
        (new / LOCK_FILE).unlink()
        if not target.exists():
            os.rename(new, target)
        elif not _exchange(new, target):
            aside = Path(tempfile.mkdtemp(prefix=f".{target.name}{MARK}", dir=target.parent))
            os.rename(target, aside)
            os.rename(new, target)
            os.rename(aside, new)  # removed with the temporary folder


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux' renameat2 with RENAME_EXCHANGE); False where the system or the
    file system cannot."""
    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    at_cwd, exchange = -100, 2
    if renameat2(at_cwd, os.fsencode(a), at_cwd, os.fsencode(b), exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def unwritable(path, folder: bool) -> str | None:
    """Why ``path`` cannot be written as a file (``folder`` False) or a folder (None when it can): it is
    one of the other kind, or an ancestor is a file."""
    path = Path(path)
    if folder and path.exists() and not path.is_dir():
        return "is a file; give a folder (or a new name)"
    if not folder and path.is_dir():
        return "is a folder; give a file name"
    for parent in path.resolve().parents:
        if parent.exists():
            return None if parent.is_dir() else f"{parent.name} is a file, not a folder; choose another place"
    return None


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


if __name__ == "__main__":
    _clean_after_writer(int(sys.argv[1]))
