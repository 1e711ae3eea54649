"""The discovery benchmark (issue 37): ``pcbdyn diagnose`` on cases drawn from seeds, each judged
against its truth (:mod:`score`), and the split's figures printed.

    python benchmarks/discovery/run.py dev [--n 50] [--jobs 2] [--workers 1] [--scheduler tcp://...]
    python benchmarks/discovery/run.py report            # seeds 1000-1199: run to report, never to tune
    python benchmarks/discovery/run.py 0-9,17            # given seeds
    python benchmarks/discovery/run.py dev-housings      # the ribbed housings of the same seeds (:mod:`housings`)
    python benchmarks/discovery/run.py h0-3,h1000        # given housings

Cases are made on demand (:mod:`make`, cached); each diagnosis runs as the command line does (a
child process, ``--json``), ``--jobs`` of them at once on local processes or on a Dask cluster, and
its JSON is kept beside the case under a tag (``--tag``, default the git commit of pcbdyn) so that
a split is judged again without running it twice. Prints one row per case and the figures the
issue's acceptance names: effects of detectable size found, noise-only cases clean, effect cases
with no invented effect, the median error after, 1- and 2-sigma coverage, and the wall time per case.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

from cases import DEV, REPORT  # noqa: E402
from detectability import DETECTABLE_CHI2  # noqa: E402
from make import cache_dir, case_names, made  # noqa: E402
from score import judge  # noqa: E402
from truth_error import largest_error  # noqa: E402


def _tag() -> str:
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                             check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "pcbdyn"], cwd=ROOT, capture_output=True,
                               text=True).stdout.strip()
        return rev + ("-dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "untagged"


def run_case(name: str, options: dict, shared=None) -> dict:
    """Make case ``name`` (a board ``s0012`` or a housing ``h0012``) and diagnose it (or reuse the result
    kept under the tag and the truth's key); a case that cannot be made is a result with ``exit`` None
    and the reason."""
    seed, housing = int(name[1:]), name.startswith("h")
    try:
        folder = made(name, options["cache"])
    except Exception as exc:  # the generator's own failure: reported per case, the split goes on
        return {"seed": seed, "wall_s": 0.0, "exit": None, "stderr_tail": f"{type(exc).__name__}: {exc}",
                "diagnosis": None}
    key = json.loads((folder / "truth.json").read_text())["key"]
    out = folder / f"result-{options['tag']}-{key}.json"
    if out.exists() and not options["again"]:
        return json.loads(out.read_text())
    js = folder / f"diagnose-{options['tag']}.json"
    cmd = [sys.executable, "-m", "pcbdyn.cli", "diagnose", str(folder / ("box.toml" if housing else "board.toml")),
           str(folder / "test.uff"),
           "--noise", "f={:g},shape={:g}".format(*json.loads((folder / "truth.json").read_text())["case"]["noise"]),
           "--json", str(js), "--out", str(folder / f"out-{options['tag']}"), "--force",
           "--workers", str(options["workers"])]
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    (folder / f"diagnose-{options['tag']}.log").write_text(p.stdout + p.stderr)  # the whole progress log
    result = {"seed": seed, "wall_s": wall, "exit": p.returncode, "stderr_tail": p.stderr[-2000:],
              "diagnosis": json.loads(js.read_text()) if js.exists() else None}
    out.write_text(json.dumps(result, indent=1))
    return result


#: report seeds a session has read case by case (their files, their diagnosis step by step): no longer
#: unseen, so the figures are printed without them too (kept here, not in :mod:`cases`, whose code is
#: part of the cached cases' key). 1021: its failure followed into the search's start from the modes
#: without a partner; 1022: its point mass beside a hinged edge (2026-11-30); 1023: a scan of the kept
#: results for parameters fitted onto a bound listed it beside dev seeds 20 and 21 (2026-12-01). 1002, 1005:
#: a scan of kept results for effects whose standard deviation reaches their size listed their effects
#: beside the dev ones that led to :func:`pcbdyn.diagnosis.merge.resolved` (2026-12-05). 1020: its internal
#: error followed into :func:`pcbdyn.diagnosis.at_points.as_points` and its truth read beside the fix's result
#: (2026-12-05, later). 1000, 1006, 1024: their effects and intervals read beside their truths while looking
#: for a pattern among the invented effects (2026-12-06; nothing was changed from them).
SEEN = {1000, 1002, 1005, 1006, 1020, 1021, 1022, 1023, 1024}


def _pct(k: int, n: int) -> str:
    return f"{k}/{n} ({100 * k / n:.0f} %)" if n else "-"


def summary(rows: list) -> dict:
    """The acceptance figures over judged cases ``rows`` [(truth, result, verdict)]."""
    atoms = [a for _, _, v in rows for a in v["atoms"]]
    det = [a for a in atoms if a["detectable"]]
    clean = [v for _, _, v in rows if v["noise_only_case"]]
    eff = [v for _, _, v in rows if not v["noise_only_case"]]
    cov = [a["covered"] for a in det if a.get("covered") is not None]
    cov1 = [a["covered_1sigma"] for a in det if a.get("covered_1sigma") is not None]
    after = [v["after"] for _, _, v in rows if "after" in v]
    walls = [r["wall_s"] for _, r, _ in rows]
    own = [v["truth_error_pct"] for _, _, v in rows if v.get("truth_error_pct") is not None]
    return {
        "cases": len(rows), "crashed": sum(r["exit"] != 0 for _, r, _ in rows),
        "found_detectable": (sum(a["found"] for a in det), len(det)),
        "placed_detectable": (sum(a["placed"] for a in det), len(det)),
        "clean_noise_only": (sum(not v["n_reported"] for v in clean), len(clean)),
        "no_invented": (sum(not v["invented"] for v in eff), len(eff)),
        "covered_2sigma": (sum(cov), len(cov)), "covered_1sigma": (sum(cov1), len(cov1)),
        "median_after_pct": float(np.median(after)) if after else None,
        "after_le_0.5": (sum(a <= 0.5 for a in after), len(after)),
        "median_truth_error_pct": float(np.median(own)) if own else None,
        "median_wall_s": float(np.median(walls)) if walls else None, "max_wall_s": max(walls) if walls else None,
        "stage_share": stage_share([r for _, r, _ in rows]),
    }


def stage_share(results: list) -> dict:
    """{diagnosis stage: its share of the summed wall time of the diagnoses that kept their stages'
    seconds} (statistics.stage_seconds), the largest first: where a speed-up is to be looked for."""
    summed: dict = {}
    for r in results:
        for key, t in (((r.get("diagnosis") or {}).get("statistics") or {}).get("stage_seconds") or {}).items():
            summed[key] = summed.get(key, 0.0) + t
    total = sum(summed.values())
    return {k: t / total for k, t in sorted(summed.items(), key=lambda kv: -kv[1])} if total else {}


def main(argv=None):
    import argparse

    from pcbdyn.parallel import run_jobs

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("split", help="dev, report, or seeds such as 0-9,17")
    ap.add_argument("--n", type=int, default=None, help="the first N seeds of the split")
    ap.add_argument("--jobs", type=int, default=2, help="cases at once (local processes)")
    ap.add_argument("--workers", type=int, default=1, help="diagnose --workers of each case")
    ap.add_argument("--scheduler", default=None, help="a Dask scheduler address: the cases run there")
    ap.add_argument("--tag", default=None, help="the name results are kept under (default: the git commit)")
    ap.add_argument("--again", action="store_true", help="diagnose again even where a result is kept")
    ap.add_argument("--cache", default=None)
    ap.add_argument("--json", default=None, help="write the rows and figures as JSON")
    a = ap.parse_args(argv)
    splits = {"dev": DEV, "report": REPORT}
    todo = ([f"s{s:04d}" for s in splits[a.split]] if a.split in splits else
            [f"h{s:04d}" for s in splits[a.split.split("-")[0]]] if a.split.endswith("-housings") else
            case_names(a.split))
    todo = todo[:a.n] if a.n else todo
    options = {"cache": Path(a.cache) if a.cache else cache_dir(), "tag": a.tag or _tag(), "again": a.again,
               "workers": a.workers}
    print(f"{len(todo)} cases, tag {options['tag']}, load {os.getloadavg()[0]:.1f}", flush=True)
    rows = []
    t0 = time.perf_counter()
    for (name, _), result in run_jobs(run_case, [(s, options) for s in todo], None, workers=a.jobs,
                                      scheduler=a.scheduler):
        if result["exit"] is None:
            print(f"{name} not made: {result['stderr_tail']}", flush=True)
            continue
        truth = json.loads((options["cache"] / name / "truth.json").read_text())
        v = judge(truth, result["diagnosis"], DETECTABLE_CHI2)
        v["truth_error_pct"] = own = largest_error(options["cache"] / name)
        rows.append((truth, result, v))
        kinds = ",".join(e["kind"] for e in truth["case"]["effects"]) or "-"
        marks = " ".join(f"{x['type'][:6]}{'+' if x['found'] else ('~' if x['placed'] else '-')}"
                         f"{'' if x['detectable'] else '(u)'}" for x in v["atoms"])
        print(f"{name} {truth['case']['hold']:<9} {kinds:<26} {marks:<34} inv {len(v['invented'])} "
              f"after {v.get('after', float('nan')):6.2f} % (po {v.get('parameters_only', float('nan')):6.2f}, "
              f"truth's own {float('nan') if own is None else own:4.2f}) "
              f"{result['wall_s']:5.0f} s{'' if result['exit'] == 0 else ' EXIT ' + str(result['exit'])} "
              f"[load {os.getloadavg()[0]:.1f}]", flush=True)
    print(f"\n{len(rows)} cases in {time.perf_counter() - t0:.0f} s")
    unseen = [r for r in rows if r[0]["case"]["hold"] == "housing" or r[0]["case"]["seed"] not in SEEN]
    s = summary(rows)
    _print(s)
    if 0 < len(unseen) < len(rows):
        print(f"without the report seeds read case by case ({', '.join(map(str, sorted(SEEN)))}: SEEN):")
        _print(summary(unseen))
    if a.json:
        listed = [v | {"seed": t["case"]["seed"], "housing": t["case"]["hold"] == "housing"} for t, _, v in rows]
        Path(a.json).write_text(json.dumps({"summary": s, "summary_unseen": summary(unseen), "rows": listed},
                                           indent=1, default=float))


def _print(s: dict) -> None:
    print(f"  {s['cases']} cases (crashed {s['crashed']})")
    print(f"  effects of detectable size found (kind, place, magnitude): {_pct(*s['found_detectable'])}; "
          f"placed: {_pct(*s['placed_detectable'])}")
    print(f"  noise-only cases clean: {_pct(*s['clean_noise_only'])}")
    print(f"  effect cases with no invented effect: {_pct(*s['no_invented'])}")
    print(f"  coverage of the magnitudes placed: 2-sigma {_pct(*s['covered_2sigma'])} (stated 95 %), "
          f"1-sigma {_pct(*s['covered_1sigma'])} (stated 68 %)")
    print(f"  error after: median {s['median_after_pct']} %, <= 0.5 %: {_pct(*s['after_le_0.5'])}")
    print(f"  the truth's own discretisation error (truth_error.py, the largest over a case's modes): median "
          f"{s['median_truth_error_pct']} %")
    print(f"  wall per case: median {s['median_wall_s']:.0f} s, slowest {s['max_wall_s']:.0f} s")
    if s["stage_share"]:
        print("  where the time went: " + ", ".join(f"{k} {100 * v:.0f} %" for k, v in s["stage_share"].items()))


if __name__ == "__main__":
    main()
