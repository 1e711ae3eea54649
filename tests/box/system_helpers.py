"""Systems for the tests: a housing of two side walls and a back plate (clamped along their lower edges)
holding the example shelf card (examples/housed_cards/card_guides.toml) in wedge-lock guides between the
walls, with the walls' material and thickness chosen by the test."""

import shutil
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "housed_cards"
CARD = EXAMPLES / "card_guides.toml"


def _plate(name, origin, u, v, t_mm):
    mm = lambda p: "[" + ", ".join(f'"{c} mm"' for c in p) + "]"  # noqa: E731
    return (f'[[plates]]\nname = "{name}"\norigin = {mm(origin)}\nu = {mm(u)}\nv = {mm(v)}\n'
            f'thickness = "{t_mm} mm"\nmaterial = "wall"\n\n')


def housing(tmp_path, t_mm: float, material: str, cards: bool = True, name: str = "box.toml") -> Path:
    """The housing (walls ``t_mm`` thick of ``material``: the lines of a [materials] table) with the shelf in its
    guides (``cards``) or empty; the card's file is copied beside the box."""
    shutil.copy(CARD, Path(tmp_path) / "card.toml")
    text = f'[box]\nname = "housing"\nmesh_size = "10 mm"\n\n[materials.wall]\n{material}\n\n'
    text += _plate("left", (0, 0, 0), (0, 140, 0), (0, 0, 120), t_mm)
    text += _plate("right", (200, 0, 0), (0, 140, 0), (0, 0, 120), t_mm)
    text += _plate("back", (0, 140, 0), (200, 0, 0), (0, 0, 120), t_mm)
    text += "".join(f'[[supports]]\nplate = "{p}"\nedge = "v0"\ntype = "clamped"\n\n' for p in ("left", "right", "back"))
    if cards:
        text += ('[[cards]]\nname = "card1"\nboard = "card.toml"\norigin = ["0 mm", "10 mm", "60 mm"]\n'
                 'u = [0, 1, 0]\nv = [1, 0, 0]\n\n')
    out = Path(tmp_path) / name
    out.write_text(text)
    return out


STEEL = 'E = "210 GPa"\nnu = 0.3\nrho = "7850 kg/m^3"'
ALUMINIUM = 'E = "70 GPa"\nnu = 0.33\nrho = "2700 kg/m^3"'
