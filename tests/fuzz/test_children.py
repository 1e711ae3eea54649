"""Work run in children of a fork server (gmsh): the same memory for every child, crashes and time limits
reported, and a server that dies with pcbdyn."""

import ctypes
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import pcbdyn
from pcbdyn.children import run_forked


def _first_block() -> int:
    """Where the first 4 kB block a child allocates lies in its memory."""
    return ctypes.addressof(ctypes.create_string_buffer(4096))


def test_children_start_from_the_same_memory_whatever_the_caller_allocated():
    """gmsh breaks ties between equal quad recombinations by where its objects lie in memory. Children
    forked from the caller inherited its heap, so one board gave one of two meshes run to run; children
    of the fork server all start from one memory, and allocate alike."""
    first = run_forked(_first_block)
    held = [ctypes.create_string_buffer(4096 + 64 * k) for k in range(300)]
    assert run_forked(_first_block) == first
    del held


def _abort():
    os.abort()


def test_a_crashed_child_is_named_and_the_next_call_works():
    with pytest.raises(RuntimeError, match="SIGABRT"):
        run_forked(_abort, what="the crash")
    assert run_forked(os.getpid) != os.getpid()


def test_an_exception_comes_back_and_a_late_child_is_stopped():
    with pytest.raises(ZeroDivisionError):
        run_forked(divmod, (1, 0))
    with pytest.raises(TimeoutError, match="within 0.5 s"):
        run_forked(signal.pause, timeout=0.5, what="a pause")
    assert run_forked(divmod, (7, 2)) == (3, 1)


def test_the_fork_server_dies_with_a_killed_run():
    """The server is a process of its own; a run killed by SIGKILL must not leave it behind."""
    from processes import alive

    code = ("import os, sys, time; from pcbdyn.children import run_forked; run_forked(os.getpid); "
            "from pcbdyn.children import _SERVER; print(_SERVER['now']['proc'].pid, flush=True); time.sleep(60)")
    env = {**os.environ, "PYTHONPATH": str(Path(pcbdyn.__file__).resolve().parents[1])}
    run = subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, text=True)
    try:
        server = int(run.stdout.readline())
        assert alive(server)
        run.kill()
        run.wait()
        t_end = time.monotonic() + 5
        while alive(server) and time.monotonic() < t_end:
            time.sleep(0.02)
        assert not alive(server), "the fork server outlived the killed run"
    finally:
        run.kill()
        run.wait()
