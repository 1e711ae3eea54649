"""The model-form budget per effect kind from the development split (issue 37, item 4: the reported
intervals cover the truth at their stated rates on the generated benchmark).

    python benchmarks/discovery/calibrate.py TAG            # the dev results kept under TAG (run.py --tag)
    python benchmarks/discovery/calibrate.py TAG 0-14,16-27

Reads the results :mod:`run` kept for the development seeds (a report seed is refused: the report
split is run to report, never to tune), judges each (:func:`score.judge`) and, per kind of the
reported effect (its ``kind``), collects the relative errors of the magnitudes placed on a truth.
Prints them and the budget by the rule the bench's :data:`pcbdyn.diagnosis.uncertainty.MODEL_FORM`
was set by (half the 90th percentile, so that two standard deviations cover nine in ten), for the
kinds placed at least :data:`MIN_PLACED` times; the others keep the bench's. The printed table is
what ``MODEL_FORM_BY_KIND`` holds.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[1]))

from cases import DEV  # noqa: E402
from make import cache_dir, seeds  # noqa: E402
from score import judge  # noqa: E402

#: a kind's own budget needs at least this many magnitudes placed on the development split
MIN_PLACED = 4


def errors(tag: str, todo, cache: Path) -> dict:
    """{reported kind: [(seed, relative error of the magnitude)]} over the seeds ``todo`` judged under ``tag``."""
    out: dict = {}
    for seed in todo:
        folder = cache / f"s{seed:04d}"
        kept = sorted(folder.glob(f"result-{tag}-*.json"))
        if not kept:
            continue
        diagnosis = json.loads(kept[0].read_text())["diagnosis"]
        if not diagnosis:
            continue
        for atom in judge(json.loads((folder / "truth.json").read_text()), diagnosis, 0.0)["atoms"]:
            if atom.get("reported") is not None and atom["magnitude"]:
                out.setdefault(atom["reported_kind"], []).append((seed, atom["reported"] / atom["magnitude"] - 1.0))
    return out


def budgets(found: dict, floor: float, least: int = MIN_PLACED) -> dict:
    """{kind: budget}: half the 90th percentile of the |relative errors| of each kind in ``found`` placed
    at least ``least`` times, never below ``floor`` (the bench's budget)."""
    return {k: max(floor, 0.5 * float(np.quantile(np.abs([e for _, e in rows]), 0.9)))
            for k, rows in found.items() if len(rows) >= least}


def main(argv=None):
    import argparse

    from pcbdyn.diagnosis.uncertainty import MODEL_FORM

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tag", help="the tag the dev results were kept under (run.py --tag)")
    ap.add_argument("seeds", nargs="?", default=None, help="dev seeds such as 0-14,16-27 (default: all of dev)")
    ap.add_argument("--cache", default=None)
    a = ap.parse_args(argv)
    todo = list(DEV) if a.seeds is None else seeds(a.seeds)
    if any(s not in DEV for s in todo):
        ap.error(f"seeds {sorted(s for s in todo if s not in DEV)} are not development seeds "
                 f"({DEV.start}-{DEV.stop - 1}): the report split is never used to tune")
    found = errors(a.tag, todo, Path(a.cache) if a.cache else cache_dir())
    chosen = budgets(found, MODEL_FORM)
    print(f"{'kind':<18} {'placed':>6}  {'|error| [%], sorted':<58} {'budget [%]':>10}")
    for k, rows in sorted(found.items()):
        e = np.sort(np.abs([x for _, x in rows]))
        print(f"{k:<18} {e.size:>6}  {' '.join(f'{100 * x:.1f}' for x in e):<58} "
              f"{100 * chosen.get(k, MODEL_FORM):>10.1f}{'' if k in chosen else ' (the bench: too few)'}")
    print("MODEL_FORM_BY_KIND = {" + ", ".join(f'"{k}": {v:.2f}' for k, v in sorted(chosen.items())) + "}")


if __name__ == "__main__":
    main()
