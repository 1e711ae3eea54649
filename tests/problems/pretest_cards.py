"""The six-part card with one thickness parameter per part (t_U1..t_U6, from the library's 3.5 mm), the
card of issue 41's configuration design (tests/problems/test_pretest_configs.py and
benchmarks/bench_pretest_configs.py)."""

from pathlib import Path

import numpy as np
import tomlkit

from pcbdyn.board import load_board

CARD = Path(__file__).resolve().parents[2] / "examples/six_part_card"
NAMES = [f"t_U{i}" for i in range(1, 7)]
#: the part thicknesses [m] of the card "tested" (the library's are 3.5 mm)
TRUE_T = np.array([4.2, 3.0, 4.0, 2.9, 3.9, 4.4]) * 1e-3


def six_thickness_card(path: Path) -> Path:
    """The card (its configurations c2, c3 and [analysis] modes = 7 kept) with t_U1..t_U6 as its parameters
    instead of the families and E, written to ``path``."""
    text = (CARD / "board.toml").read_text().split("[[parameters]]")[0].rstrip() + "\n"
    text += "".join(f'\n[[parameters]]\nname = "t_U{i}"\ntarget = "components.U{i}.thickness"\n'
                    'bounds = ["2 mm", "10 mm"]\n' for i in range(1, 7))
    path.write_text(text + "\n[analysis]\nmodes = 7\n")
    return path


def with_thicknesses(card: Path, t, path: Path, mesh_size: str | None = None) -> Path:
    """``card`` (with the parameters :data:`NAMES`) with the parts' thicknesses ``t`` [m] written into their
    targets as ``pcbdyn update`` writes them, and ``mesh_size`` where given, to ``path``."""
    load_board(card).write_updated(dict(zip(NAMES, t)), path, source="the test's truth")
    if mesh_size is not None:
        doc = tomlkit.parse(path.read_text())
        doc["board"]["mesh_size"] = mesh_size
        path.write_text(tomlkit.dumps(doc))
    return path
