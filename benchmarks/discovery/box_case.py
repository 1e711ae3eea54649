"""The housing case of issue 37: the example ribbed box (examples/ribbed_box) whose 80 g relay on the
back plate is left out of the box.toml handed to diagnose, with its declared values about 30 % off
(E and rho of the upper plate, the rib heights: the first modes come out swapped), tested at the
example's 143 points in x, y and z. The truth is the example itself, meshed twice as fine and solved
in OpenSees; the noise is pcbdyn's (0.2 % frequencies, 2 % shapes).

    python benchmarks/discovery/box_case.py [--cache DIR]

writes ``box80/`` in the discovery cache (box.toml, truth.toml, test.uff, truth.json).
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

from make import ZETA, cache_dir  # noqa: E402
from seen import EXTRA_MODES  # noqa: E402

EXAMPLE = ROOT / "examples" / "ribbed_box" / "box.toml"
#: the handed box's declared values (the example's, i.e. the truth's, in brackets)
HANDED = {"E": "50 GPa", "rho": "3500 kg/m^3", "h_side": "7 mm", "h_back": "13 mm", "h_upper_x": "7 mm"}
TRUTH = {"relay_mm": (100.0, 95.0), "plate": "back", "mass": 0.080, "E_upper": 70e9, "rho_upper": 2700.0,
         "h_side": 10e-3, "h_back": 10e-3, "h_upper_x": 10e-3}
TEST_MODES = 12
SHELL = "ASDShellQ4"


def handed_text() -> str:
    """The example with the relay left out and its declared values off."""
    text = EXAMPLE.read_text()
    text, n = re.subn(r'\n\[\[masses\]\]\nname = "relay"\nplate = "back"\nat = \[[^\]]*\]\nmass = "80 g"\n', "\n", text)
    assert n == 1, "the relay block of the example box was not found"
    upper = text.index('name = "upper"')
    head, tail = text[:upper], text[upper:]
    tail = tail.replace('material = "al"', 'material = "al_upper"', 1)
    text = head + tail
    text = text.replace("[[plates]]", f'[materials.al_upper]\nE = "{HANDED["E"]}"\nnu = 0.33\nrho = "{HANDED["rho"]}"\n\n'
                        "[[plates]]", 1)
    for ribs, h in (("left_v", HANDED["h_side"]), ("right_v", HANDED["h_side"]), ("back_h", HANDED["h_back"]),
                    ("upper_x", HANDED["h_upper_x"])):
        text = re.sub(rf'(name = "{ribs}\d"\n(?:[^\n]*\n)*?height = )"10 mm"', rf'\1"{h}"', text)
    return text


def make(cache: Path | None = None) -> Path:
    from opensees_truth import solve_opensees

    from pcbdyn.box import load_box
    from pcbdyn.fe.modal import Modes as ModelModes
    from pcbdyn.fe.probe import model_probe
    from pcbdyn.testdata.csvio import read_points_csv
    from pcbdyn.testdata.noise import Noise
    from pcbdyn.testdata.simulate import simulate_test
    from pcbdyn.testdata.uff import write_uff

    folder = (cache or cache_dir()) / "box80"
    if (folder / "truth.json").exists() and (folder / "test.uff").exists():
        return folder
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "box.toml").write_text(handed_text())
    truth = EXAMPLE.read_text().replace('mesh_size = "10 mm"', 'mesh_size = "5 mm"')
    (folder / "truth.toml").write_text(truth)
    box = load_box(folder / "truth.toml")
    model = box.build().model
    f, shapes = solve_opensees(model, TEST_MODES + EXTRA_MODES, shell=SHELL)
    f, shapes = f[:TEST_MODES], shapes[..., :TEST_MODES]  # a test in x, y and z sees every mode
    points, dofs = read_points_csv(EXAMPLE.with_name("points.csv"))
    read = model_probe(model, points.xyz[points.index(dofs.point_ids)], dofs.directions, tol=0.02).P
    u = np.asarray(read @ shapes.reshape(-1, shapes.shape[-1]))
    test = simulate_test(ModelModes(f, u, np.zeros((u.shape[0], 0)), None), points, dofs, np.eye(u.shape[0]),
                         zeta=ZETA, noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=80)
    write_uff(folder / "test.uff", test)
    (folder / "truth.json").write_text(json.dumps({"truth": TRUTH, "frequencies_hz": f.tolist(), "shell": SHELL},
                                                  indent=1))
    return folder


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", default=None)
    a = ap.parse_args()
    out = make(Path(a.cache) if a.cache else None)
    print(out, json.loads((out / "truth.json").read_text())["frequencies_hz"])
