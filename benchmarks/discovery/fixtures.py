"""A few drawn cases kept as test fixtures (issue 37: the suite runs a handful of generated cases):
the handed board.toml, the points and the truth's clean modes from OpenSees, with the case (its
hidden effects and true values) to judge a diagnosis by; the test adds pcbdyn's noise, as the
benchmark does.

    python benchmarks/discovery/fixtures.py 3,12 [--to tests/diagnosis/generated]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from make import make, seeds  # noqa: E402

TO = HERE.parents[1] / "tests" / "diagnosis" / "generated"


def export(seed: int, to: Path = TO) -> Path:
    """tests/diagnosis/generated/s<seed>.json from the (made or cached) case ``seed``."""
    folder = make(seed)
    truth = json.loads((folder / "truth.json").read_text())
    z = np.load(folder / "shapes_z.npy")
    data = {"seed": seed, "source": "benchmarks/discovery (OpenSees, twice the model's mesh)",
            "board_toml": (folder / "board.toml").read_text(), "case": truth["case"],
            "frequencies_hz": truth["frequencies_hz"], "shapes_z": np.round(z, 8).tolist(),
            "signal_chi2": truth["signal_chi2"]}
    to.mkdir(parents=True, exist_ok=True)
    out = to / f"s{seed:04d}.json"
    out.write_text(json.dumps(data, indent=0) + "\n")
    return out


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("seeds")
    ap.add_argument("--to", default=str(TO))
    a = ap.parse_args()
    for s in seeds(a.seeds):
        print(export(s, Path(a.to)))
