"""The six-part card with one thickness parameter per part (t_U1..t_U6, from the library's 3.5 mm), the
card of issue 41's configuration design (tests/problems/test_pretest_configs.py and
benchmarks/bench_pretest_configs.py)."""

import re
from pathlib import Path

CARD = Path(__file__).resolve().parents[2] / "examples/six_part_card"
NAMES = [f"t_U{i}" for i in range(1, 7)]
#: the part thicknesses [m] of the card "tested" (the library's are 3.5 mm)
TRUE_T = (4.2e-3, 3.0e-3, 4.0e-3, 2.9e-3, 3.9e-3, 4.4e-3)


def six_thickness_card(path: Path) -> Path:
    """The card (its configurations c2, c3 and [analysis] modes = 7 kept) with t_U1..t_U6 as its parameters
    instead of the families and E, written to ``path``."""
    text = (CARD / "board.toml").read_text().split("[[parameters]]")[0].rstrip() + "\n"
    text += "".join(f'\n[[parameters]]\nname = "t_U{i}"\ntarget = "components.U{i}.thickness"\n'
                    'bounds = ["2 mm", "10 mm"]\n' for i in range(1, 7))
    path.write_text(text + "\n[analysis]\nmodes = 7\n")
    return path


def with_thicknesses(card: Path, t, path: Path, mesh_size: str | None = None) -> Path:
    """``card`` (parts at the library's thickness) with the parts' thicknesses ``t`` [m], and ``mesh_size``
    where given, written to ``path``."""
    text = card.read_text()
    if mesh_size is not None:
        text = re.sub(r'mesh_size = ".*"', f'mesh_size = "{mesh_size}"', text)
    for i, ti in enumerate(t):
        text = text.replace(f'ref = "U{i + 1}"\n', f'ref = "U{i + 1}"\nthickness = "{ti * 1e3:.6g} mm"\n')
    path.write_text(text)
    return path
