"""Kill test (issue 22): runs that write results are stopped by SIGKILL at random points, and what they
leave is checked. Each case first runs to the end twice into its output folder (the earlier results, and
a check that the command writes the same bytes each time); then every trial starts the same run again
and kills it at a random time within the first 80 % of its usual duration. After each kill:

- every earlier file (inputs and earlier results) has its earlier SHA-256 (a run rewrites a result with
  the same bytes, so any other hash is a half-written or lost file);
- temporary files where the results go (``.*.pcbdyn~*``) and stale temporary folders of the picture
  renderer in the system's temporary folder: those a kill leaves are counted (tmp_at_kill), and those
  still there after the next complete run of the case, whose writes must remove them (tmp_after_next);
- how many earlier files the run had already rewritten (same bytes, new time) before it was killed, to
  show the kills land among the writes too;
- no child process of the killed run (the gmsh mesher, the picture renderer) is still alive 0.5 s later.

Cases: ``build --all-configs`` of the six-part card (three configurations, pictures), ``update`` of the
card against the thesis' measured frequencies (iterations.png, tables, board.updated.toml) and ``build``
of the plain plate with its JSON. Prints per case and in all: kills, files changed, temporary files
after the kill and after the next run, orphaned processes; exits 1 on any change, leftover or orphan.

Run: python benchmarks/kill_test.py [--kills 50] [--seed N]
"""

from __future__ import annotations

import argparse
import fcntl
import hashlib
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "fuzz"))

from processes import alive, descendants  # noqa: E402

from pcbdyn.atomic import MARK  # noqa: E402

CARD = ROOT / "examples" / "six_part_card"
PLATE = ROOT / "examples" / "plain_plate"
VIEWS = "build"  # the case that renders mode pictures (through temporary view folders)


def cases(work: Path) -> dict:
    """name -> (argument list, folder the run writes into) for each case, inputs copied into ``work``."""
    out = {}
    for name, src, files in (("build", CARD, ("board.toml",)), ("update", CARD, ("board.toml",
                             "measured_frequencies_table_7_2.csv")), ("build-json", PLATE, ("board.toml",))):
        folder = work / name
        folder.mkdir()
        for f in files:
            shutil.copy(src / f, folder / f)
        out[name] = folder
    b = out["build"]
    u = out["update"]
    p = out["build-json"]
    return {
        "build": (["build", b / "board.toml", "--all-configs", "--out", b / "out", "--json", b / "out" / "modes.json"],
                  b),
        "update": (["update", u / "board.toml", "--frequencies", u / "measured_frequencies_table_7_2.csv",
                    "--max-iter", "2", "--out", u / "out", "--force", "--json", u / "out" / "update.json"], u),
        "build-json": (["build", p / "board.toml", "--no-pictures", "--out", p / "out", "--json", p / "modes.json"], p),
    }


def start(args) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.Popen([sys.executable, "-c", "from pcbdyn.cli import main; main()", *map(str, args)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def digests(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and MARK not in p.name}


def stamps(folder: Path) -> dict:
    return {p: p.stat().st_mtime_ns for p in folder.rglob("*") if p.is_file()}


def temporaries(folder: Path, views: bool) -> list:
    """pcbdyn's temporary files in ``folder`` and, with ``views`` (a case that renders pictures), the stale
    temporary folders of the picture views in the system's temporary folder (no live process holds them)."""
    return [p for p in folder.rglob(f"*{MARK}*")] + [p for p in Path(tempfile.gettempdir()).glob(f".*{MARK}*")
                                                     if views and p.is_dir() and not held(p / ".lock")]


def held(lock: Path) -> bool:
    try:
        fd = os.open(lock, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return False
    except OSError:
        return True
    finally:
        os.close(fd)


def complete_run(args) -> float:
    t0 = time.perf_counter()
    p = start(args)
    if p.wait() != 0:
        raise SystemExit(f"pcbdyn {' '.join(map(str, args))} failed (exit {p.returncode})")
    return time.perf_counter() - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kills", type=int, default=50)
    ap.add_argument("--seed", type=int, default=int(time.time()))
    a = ap.parse_args()
    rng = random.Random(a.seed)
    print(f"seed {a.seed}", file=sys.stderr)
    totals = {}
    with tempfile.TemporaryDirectory() as tmp:
        runs = cases(Path(tmp))
        durations, earlier = {}, {}
        for name, (args, folder) in runs.items():
            complete_run(args)
            first = digests(folder)
            durations[name] = complete_run(args)
            earlier[name] = digests(folder)
            differ = sorted(k for k in first if first[k] != earlier[name].get(k))
            if differ:
                raise SystemExit(f"{name}: two complete runs wrote different bytes in {differ}: no hash test possible")
            print(f"  {name}: a complete run takes {durations[name]:.1f} s and writes {len(earlier[name])} files",
                  file=sys.stderr)
        names = list(runs)
        pending = {}  # case -> temporaries its killed runs left, until a complete run
        for k in range(a.kills):
            name = names[k % len(names)]
            args, folder = runs[name]
            t = totals.setdefault(name, {"kills": 0, "changed": 0, "lost": 0, "tmp_at_kill": 0, "tmp_after_next": 0,
                                         "orphans": 0, "finished": 0, "rewritten": 0})
            before = stamps(folder)
            delay = rng.uniform(0.3, 0.8 * durations[name])  # within the run even when the machine is less loaded
            p = start(args)
            kids, t_end = set(), time.monotonic() + delay
            while time.monotonic() < t_end and p.poll() is None:
                kids |= descendants(p.pid)
                time.sleep(0.02)
            kids |= descendants(p.pid)
            finished = p.poll() is not None
            p.kill()
            p.wait()
            t["kills"] += 1
            t["finished"] += finished
            time.sleep(0.5)
            t["orphans"] += sum(alive(c) for c in kids)
            for c in kids:  # leave no process behind whatever happened
                if alive(c):
                    os.kill(c, signal.SIGKILL)
            after = stamps(folder)
            t["rewritten"] += sum(1 for f, m in before.items() if after.get(f, m) != m)
            now = digests(folder)
            t["changed"] += sum(1 for f, h in earlier[name].items() if f in now and now[f] != h)
            t["lost"] += sum(1 for f in earlier[name] if f not in now)
            left = set(temporaries(folder, name == VIEWS))
            new = left - pending.get(name, set())
            t["tmp_at_kill"] += len(new)
            if finished:  # a complete run: its writes have removed what earlier kills left
                t["tmp_after_next"] += len(left & pending.pop(name, set()))
            elif left:
                pending[name] = left
            print(f"  kill {k + 1:>3} {name:<11} at {delay:5.1f} s: {len(new)} temporaries, "
                  f"{sum(alive(c) for c in kids)} orphans", file=sys.stderr)
        for name, (args, folder) in runs.items():  # a complete run of each case: it removes what kills left
            complete_run(args)
            left = set(temporaries(folder, name == VIEWS))
            totals[name]["tmp_after_next"] += len(left & pending.pop(name, set()))
            totals[name]["changed"] += sum(1 for f, h in earlier[name].items() if digests(folder).get(f) != h)
    cols = ["kills", "finished", "rewritten", "changed", "lost", "tmp_at_kill", "tmp_after_next", "orphans"]
    print(f"{'case':<12}" + "".join(f"{c:>15}" for c in cols))
    for name, t in totals.items():
        print(f"{name:<12}" + "".join(f"{t[c]:>15}" for c in cols))
    print(f"{'all':<12}" + "".join(f"{sum(t[c] for t in totals.values()):>15}" for c in cols))
    bad = sum(t[c] for t in totals.values() for c in ("changed", "lost", "tmp_after_next", "orphans"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
