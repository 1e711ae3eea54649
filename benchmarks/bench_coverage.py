"""Coverage of the uncertainties ``pcbdyn diagnose`` reports (issue 26): over noisy repeats of bench
cases (tests/diagnosis/bench_cases.py; each repeat the same truth with its own noise seed), how often
the 2-sigma interval of each found magnitude (``interval_2sigma``: magnitude +- 2 * uncertainty, or for a
spring or an edge stiffness the chi^2 profile's) holds the true value.
Acceptance: >= 90 % over 20 repeats of three cases.

    python benchmarks/bench_coverage.py [--cases pm_transducer,gs_standoff,line_mass_free_edge]
                                        [--repeats 20] [--out out/coverage] [--json coverage.json]

Per case: repeats run, the effect found (type within 15 mm), covered by 2 sigma, the coverage, the
median |error| / sigma and the median time; a miss (not found) counts as not covered. Each
diagnose runs through :func:`bench_diagnose.one` (its JSON kept under --out).

``--calibrate FOLDER`` instead reads a finished ``bench_diagnose.py --out FOLDER`` run and prints, per
reported type and over all of them, the relative errors of the magnitudes found in every case except
the coverage cases (``--cases``) and half their 90th percentile; the one over all types is the
model-form budget (:data:`pcbdyn.diagnosis.uncertainty.MODEL_FORM`) with which two standard deviations
cover nine in ten.

    python benchmarks/bench_coverage.py --calibrate out/diagnosis_bench
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_diagnose import CASES, bc, hc, make_holdout, match, one  # noqa: E402
from test_diagnose_bench import LOC_TOL_MM  # noqa: E402

DEFAULT = "pm_transducer,gs_standoff,line_mass_free_edge"
#: repeat r of a case uses the noise seed SEED_BASE + 100 * case seed + r (apart from the bench's own)
SEED_BASE = 7000


def repeat(case, r: int, out: Path) -> dict:
    """One noisy repeat: the bench row and, per required effect of the truth, (found, |error| / sigma)."""
    rc = dataclasses.replace(case, name=f"{case.name}_r{r:02d}", seed=SEED_BASE + 100 * case.seed + r)
    row = one(rc, out)
    truth = json.loads((out / rc.name / "truth" / "truth.json").read_text())
    js = out / rc.name / "diagnose.json"
    data = json.loads(js.read_text()) if js.exists() else {}
    z, inside = [], []
    for t in truth["effects"]:
        if not t["required"]:
            continue
        e, d = match(data.get("effects", []), t)
        if e is None or d > LOC_TOL_MM:
            z.append(np.inf)
            inside.append(False)
        else:
            z.append(abs(e["magnitude"] - t["magnitude"]) / max(e["uncertainty"], 1e-300))
            lo, hi = e["interval_2sigma"]
            inside.append(bool(lo <= t["magnitude"] and (hi is None or t["magnitude"] <= hi)))
    return {**row, "z": z, "inside": inside}


def calibrate(folder: Path, held_out: list) -> dict:
    """{reported type: [relative errors]} of the magnitudes found in a bench run's ``folder``, every
    case with effects except ``held_out``; prints them and half their 90th percentile."""
    errors: dict = {}
    for name, case in CASES.items():
        js = folder / name / "diagnose.json"
        if name in held_out or case.noise_only or not js.exists():
            continue
        if name in hc.BY_NAME:
            truth = make_holdout(case, folder / name / "case")[2]
        else:
            truth = bc.make_case(case, folder / name)[2]
        data = json.loads(js.read_text())
        for t in truth["effects"]:
            e, d = match(data.get("effects", []), t)
            if t.get("required", True) and e is not None and d <= LOC_TOL_MM:
                errors.setdefault(t["type"], []).append((name, e["magnitude"] / t["magnitude"] - 1.0))
    print(f"{'type':<18} {'cases':>5} {'|error| [%], sorted':<60} {'budget [%]':>10}")
    for kind, rows in sorted(errors.items()):
        e = np.sort(np.abs([x for _, x in rows]))
        print(f"{kind:<18} {e.size:>5} {' '.join(f'{100 * x:.1f}' for x in e):<60} "
              f"{50 * np.quantile(e, 0.9):>10.1f}")
    every = np.abs([x for rows in errors.values() for _, x in rows])
    print(f"{'all':<18} {every.size:>5} {'':<60} {50 * np.quantile(every, 0.9):>10.1f}")
    return errors


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default=DEFAULT, help="comma-separated bench cases with effects")
    ap.add_argument("--repeats", type=int, default=20)
    ap.add_argument("--out", default=str(ROOT / "out" / "coverage"))
    ap.add_argument("--json", default=None, help="write the rows as JSON")
    ap.add_argument("--calibrate", metavar="FOLDER", help="a bench_diagnose.py --out folder: print the model-form "
                    "budget from its cases other than --cases")
    a = ap.parse_args(argv)
    names = a.cases.split(",")
    if a.calibrate:
        calibrate(Path(a.calibrate), names)
        return
    bad = [n for n in names if n not in bc.BY_NAME or bc.BY_NAME[n].noise_only]
    if bad:
        ap.error(f"not bench cases with effects: {bad}; use some of "
                 f"{', '.join(n for n, c in bc.BY_NAME.items() if not c.noise_only)}")
    out = Path(a.out)
    print(f"{'case':<22} {'runs':>4} {'found':>5} {'in 2 sigma':>10} {'coverage':>8} {'med |e|/sigma':>13} {'med time [s]':>12}")
    rows, total = [], [0, 0]
    for n in names:
        runs = []
        for r in range(a.repeats):
            runs.append(repeat(CASES[n], r, out))
            print(f"  {n} repeat {r + 1} of {a.repeats}: |error|/sigma {np.round(runs[-1]['z'], 2).tolist()} "
                  f"({runs[-1]['diagnose_s']:.0f} s, load {runs[-1]['load']:.1f})", file=sys.stderr, flush=True)
        z = np.concatenate([np.asarray(x["z"], float) for x in runs])
        found, covered = int(np.isfinite(z).sum()), sum(sum(x["inside"]) for x in runs)
        total[0] += covered
        total[1] += z.size
        rows.append({"case": n, "runs": runs, "found": found, "covered": covered, "coverage": covered / max(z.size, 1)})
        print(f"{n:<22} {len(runs):>4} {found:>5} {covered:>10} {100 * covered / max(z.size, 1):>7.0f}% "
              f"{np.median(z):>13.2f} {np.median([x['diagnose_s'] for x in runs]):>12.1f}", flush=True)
    print(f"\nall: {total[0]} of {total[1]} found magnitudes within 2 sigma of the truth "
          f"({100 * total[0] / max(total[1], 1):.0f} %; acceptance >= 90 %)")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1, default=float))


if __name__ == "__main__":
    main()
