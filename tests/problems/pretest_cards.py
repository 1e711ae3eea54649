"""The six-part card with one thickness parameter per part (t_U1..t_U6, from the library's 3.5 mm), the
card of issue 41's configuration design (tests/problems/test_pretest_configs.py and
benchmarks/bench_pretest_configs.py)."""

from pathlib import Path

CARD = Path(__file__).resolve().parents[2] / "examples/six_part_card"
NAMES = [f"t_U{i}" for i in range(1, 7)]


def six_thickness_card(path: Path) -> Path:
    """The card (its configurations c2, c3 and [analysis] modes = 7 kept) with t_U1..t_U6 as its parameters
    instead of the families and E, written to ``path``."""
    text = (CARD / "board.toml").read_text().split("[[parameters]]")[0].rstrip() + "\n"
    text += "".join(f'\n[[parameters]]\nname = "t_U{i}"\ntarget = "components.U{i}.thickness"\n'
                    'bounds = ["2 mm", "10 mm"]\n' for i in range(1, 7))
    path.write_text(text + "\n[analysis]\nmodes = 7\n")
    return path
