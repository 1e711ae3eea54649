"""The processes a run has started, read from Linux's /proc: used to check that a killed run leaves no child
behind (tests/fuzz/test_signatures.py, benchmarks/kill_test.py)."""

from __future__ import annotations

from pathlib import Path


def descendants(pid: int) -> set:
    """Process ids of every live descendant of ``pid`` (Linux /proc): what a run has started
    and must not leave behind."""
    ppids = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            ppids[int(stat.parent.name)] = int(stat.read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
    found, todo = set(), [pid]
    while todo:
        kids = [c for c, parent in ppids.items() if parent == todo[-1] and c not in found]
        todo.pop()
        found.update(kids)
        todo += kids
    return found


def alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, ended but not yet waited for, does not)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False
