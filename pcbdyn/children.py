"""Child processes that end with pcbdyn: work run in a child of a fork server under a time limit (gmsh,
which runs in-process and cannot be interrupted from Python, and whose result depends on where its objects
lie in memory), and the rule that every child pcbdyn starts dies when
pcbdyn dies, even by SIGKILL (Linux's parent-death signal), so a killed run leaves no orphan behind."""

from __future__ import annotations

import ctypes
import importlib
import os
import pickle
import select
import signal
import struct
import subprocess
import sys
import threading
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


#: this process's fork server (:func:`run_forked`), started when first needed
_SERVER: dict = {}
_SERVER_LOCK = threading.Lock()


def run_forked(fn, args=(), timeout: float = 300.0, what: str = "the work", preload=()):
    """``fn(*args)`` run in a child forked from a fork server and its result returned (pickled back); an
    exception raised in the child is raised here. After ``timeout`` seconds the child is killed and a
    TimeoutError says so; a child that dies without a result (a crash in a C library) gives a
    RuntimeError naming how. The server is a fresh interpreter (one per process, on this one's import
    path, with the modules ``preload`` imported and a fixed hash seed) that forks a child per call and
    reads nothing itself, so every child starts from the same memory: gmsh breaks ties by where its
    objects lie in memory, and forked from a long run it gave one board one of two meshes run to run.
    Where fork is missing, ``fn`` runs in this process without a limit."""
    if not hasattr(os, "fork"):
        return fn(*args)
    with _SERVER_LOCK:
        server = _server(tuple(preload))
        data = pickle.dumps((fn, args), protocol=pickle.HIGHEST_PROTOCOL)
        try:
            _write(server["job"], b"G" + struct.pack("<Q", len(data)) + data)
            records = _records(server["out"], time.monotonic() + timeout)
        except (OSError, TimeoutError, EOFError) as exc:
            _stop(server)
            if isinstance(exc, TimeoutError):
                raise TimeoutError(f"{what} did not finish within {timeout:g} s") from None
            raise RuntimeError(f"{what}: its fork server stopped ({exc})") from None
        if "R" not in records:
            _stop(server)
            raise RuntimeError(f"{what} stopped without a result ({_how(records['S'])})")
    ok, value = pickle.loads(records["R"])
    if ok:
        return value
    raise value


def _server(preload) -> dict:
    """This process's fork server (a new one in a forked child of it, or after the last one stopped)."""
    server = _SERVER.get("now")
    if server is not None and server["pid"] == os.getpid() and server["proc"].poll() is None:
        return server
    job_r, job_w = os.pipe()
    out_r, out_w = os.pipe()
    code = f"from pcbdyn.children import serve; serve({job_r}, {out_w}, {list(preload)!r})"
    proc = subprocess.Popen([sys.executable, "-c", code], pass_fds=(job_r, out_w), preexec_fn=die_with_parent,
                            env=dict(os.environ, PYTHONHASHSEED="0", PYTHONPATH=os.pathsep.join(filter(None, sys.path))))
    os.close(job_r)
    os.close(out_w)
    _SERVER["now"] = {"pid": os.getpid(), "proc": proc, "job": job_w, "out": out_r}
    return _SERVER["now"]


def _stop(server) -> None:
    server["proc"].kill()
    server["proc"].wait()
    os.close(server["job"])
    os.close(server["out"])
    _SERVER.pop("now", None)


def serve(job: int, out: int, preload) -> None:
    """The fork server's loop: for each job announced on ``job``, a child that reads the job ((fn, args),
    pickled) from it, runs it and writes its result to ``out`` (an "R" record); then the child's exit
    code (an "S" record). Raw pipes, not :mod:`multiprocessing.connection`: receiving through it allocates
    in the server's heap at each job, and the children's memory then differed from call to call
    (tests/fuzz/test_children.py fails with it)."""
    for name in preload:
        importlib.import_module(name)
    while os.read(job, 1):
        pid = os.fork()
        if pid == 0:
            try:
                die_with_parent()
                (size,) = struct.unpack("<Q", _read(job, 8))
                try:
                    fn, args = pickle.loads(_read(job, size))
                    result = (True, fn(*args))
                except BaseException as exc:  # noqa: BLE001 - everything goes back to the caller
                    result = (False, _picklable(exc))
                data = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
                _write(out, b"R" + struct.pack("<Q", len(data)) + data)
            finally:
                os._exit(0)
        _, status = os.waitpid(pid, 0)
        _write(out, b"S" + struct.pack("<q", os.waitstatus_to_exitcode(status)))


def _records(fd: int, deadline: float) -> dict:
    """The records a job's child and the server write to ``fd``, up to the server's: {"R": the result's
    bytes (missing where the child died without one), "S": the child's exit code}."""
    records: dict = {}
    while "S" not in records:
        tag = _read(fd, 1, deadline)
        if tag == b"S":
            (records["S"],) = struct.unpack("<q", _read(fd, 8, deadline))
        else:
            (size,) = struct.unpack("<Q", _read(fd, 8, deadline))
            records["R"] = _read(fd, size, deadline)
    return records


def _read(fd: int, n: int, deadline: float | None = None) -> bytes:
    """``n`` bytes from the pipe ``fd``: TimeoutError once ``deadline`` passes, EOFError where it closes."""
    chunks, left = [], n
    while left:
        if deadline is not None:
            wait = deadline - time.monotonic()
            if wait <= 0:
                raise TimeoutError
            if not select.select([fd], [], [], min(wait, 1.0))[0]:
                continue
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            raise EOFError("the pipe closed")
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _write(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _how(exitcode: int) -> str:
    if exitcode < 0:
        return f"killed by signal {signal.Signals(-exitcode).name}"
    return f"exit status {exitcode}"


def _picklable(exc: BaseException) -> BaseException:
    try:
        pickle.dumps(exc)
        return exc
    except Exception:  # noqa: BLE001 - an exception type that does not pickle: its text
        return RuntimeError(f"{type(exc).__name__}: {exc}")
