"""The long fuzz run (issue 22): the suite's fuzzing (tests/fuzz) with fresh seeds and many more inputs.
Every input kind (board.toml, box.toml, library, study.toml, calibration.toml, map.toml, points CSV,
frequency table, PSD CSV, UFF, KiCad, quantities, targets) is mutated structurally and byte by byte and read
at its validation boundary; then mutated inputs run end to end through build, correlate and update. Prints
one line per kind (inputs, ok, clean errors, crash, hang, nan, accepted, unnamed) and the first failure of
each kind and status, and exits 1 on any failure.

Run: python benchmarks/fuzz_long.py [--per-kind 2000] [--commands 40] [--seed N]
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "fuzz"))

from fuzz_commands import CASES, simulated_test  # noqa: E402
from fuzz_kinds import MESSAGE_NAME, kinds  # noqa: E402
from fuzz_mutate import Source  # noqa: E402
from fuzz_outcome import Tally, classify  # noqa: E402


def readers(tally: Tally, per_kind: int, seed: int, folder: Path) -> None:
    for kind in kinds(folder):
        t0 = time.perf_counter()
        rng = random.Random(f"{seed}:{kind.name}")
        for _ in range(per_kind):
            item, invalid = kind.one(Source(rng=rng), folder)
            shown = MESSAGE_NAME.get(kind.name, getattr(item, "name", None))
            tally.add(classify(kind.name, lambda: kind.read(item), shown, invalid), keep=str(item)[:200])
        print(f"  {kind.name:<22} {per_kind} inputs in {time.perf_counter() - t0:.1f} s", file=sys.stderr)


def commands(tally: Tally, runs: int, seed: int, folder: Path) -> None:
    seeds = folder / "seeds"
    simulated_test(seeds)
    for name, case in CASES.items():
        t0 = time.perf_counter()
        n = max(1, runs // 4) if name == "update" else runs
        for k in range(n):
            work = folder / f"{name}-{k}"
            work.mkdir()
            tally.add(case(Source(rng=random.Random(f"{seed}:{name}:{k}")), seeds, work))
        print(f"  {name:<22} {n} runs in {time.perf_counter() - t0:.1f} s", file=sys.stderr)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-kind", type=int, default=2000, help="mutated inputs per reader kind")
    ap.add_argument("--commands", type=int, default=40, help="runs of build and correlate (update: a quarter)")
    ap.add_argument("--seed", type=int, default=int(time.time()), help="seed of the run (printed, to repeat it)")
    a = ap.parse_args()
    print(f"seed {a.seed}", file=sys.stderr)
    tally = Tally()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        readers(tally, a.per_kind, a.seed, Path(tmp))
        commands(tally, a.commands, a.seed, Path(tmp))
    print(tally.table())
    print(f"{time.perf_counter() - t0:.0f} s, seed {a.seed}")
    for (kind, status), (detail, item) in sorted(tally.examples.items()):
        print(f"\n{kind} {status}: {item}\n{detail}")
    return 1 if tally.examples else 0


if __name__ == "__main__":
    sys.exit(main())
