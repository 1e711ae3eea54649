"""Child processes that end with pcbdyn: work run in a forked child under a time limit (gmsh, which runs
in-process and cannot be interrupted from Python), and the rule that every child pcbdyn starts dies when
pcbdyn dies, even by SIGKILL (Linux's parent-death signal), so a killed run leaves no orphan behind."""

from __future__ import annotations

import ctypes
import os
import pickle
import select
import signal
import time

_PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int | None = None) -> None:
    """Ask the kernel to SIGKILL this process when its parent dies (Linux; elsewhere nothing). ``parent``:
    the pid the caller expects as parent; if it has died already, this process ends at once."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: no parent-death signal
        return
    if parent is not None and os.getppid() != parent:
        os._exit(1)


def run_forked(fn, args=(), timeout: float = 300.0, what: str = "the work"):
    """``fn(*args)`` run in a forked child and its result returned (pickled back); an exception raised in
    the child is raised here. After ``timeout`` seconds the child is killed and a TimeoutError says so;
    a child that dies without a result (a crash in a C library) gives a RuntimeError naming how. Where
    fork is missing, ``fn`` runs in this process without a limit."""
    if not hasattr(os, "fork"):
        return fn(*args)
    parent = os.getpid()
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns into the caller's stack
        try:
            os.close(r)
            die_with_parent(parent)
            try:
                out = (True, fn(*args))
            except BaseException as exc:  # noqa: BLE001 - everything goes back to the parent
                out = (False, _picklable(exc))
            with os.fdopen(w, "wb") as fh:
                fh.write(pickle.dumps(out, protocol=pickle.HIGHEST_PROTOCOL))
        finally:
            os._exit(0)
    os.close(w)
    try:
        data = _read_all(r, time.monotonic() + timeout)
    finally:
        os.close(r)
        status = _reap(pid, kill=True)
    if data is None:
        raise TimeoutError(f"{what} did not finish within {timeout:g} s")
    if not data:
        raise RuntimeError(f"{what} stopped without a result ({_how(status)})")
    ok, value = pickle.loads(data)
    if ok:
        return value
    raise value


def _read_all(fd: int, deadline: float) -> bytes | None:
    """Everything written to ``fd`` until it closes; None when ``deadline`` passes first."""
    chunks = []
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return None
        ready, _, _ = select.select([fd], [], [], min(left, 1.0))
        if ready:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)


def _reap(pid: int, kill: bool) -> int:
    """The wait status of child ``pid``, killed first when ``kill`` and still running."""
    done, status = os.waitpid(pid, os.WNOHANG)
    if done == 0:
        if kill:
            os.kill(pid, signal.SIGKILL)
        _, status = os.waitpid(pid, 0)
    return status


def _how(status: int) -> str:
    if os.WIFSIGNALED(status):
        return f"killed by signal {signal.Signals(os.WTERMSIG(status)).name}"
    return f"exit status {os.waitstatus_to_exitcode(status)}"


def _picklable(exc: BaseException) -> BaseException:
    try:
        pickle.dumps(exc)
        return exc
    except Exception:  # noqa: BLE001 - an exception type that does not pickle: its text
        return RuntimeError(f"{type(exc).__name__}: {exc}")
