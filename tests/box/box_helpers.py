"""Box files for the tests: the example box (examples/ribbed_box) as it is or with fields changed through
tomlkit, and a one-plate box written from its dimensions."""

from pathlib import Path

import tomlkit

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "ribbed_box" / "box.toml"
POINTS = EXAMPLE.with_name("points.csv")


def edited(tmp_path, changes: dict | None = None, remove=(), name: str = "box.toml", source: Path = EXAMPLE) -> Path:
    """``source`` with ``changes`` {dotted path: TOML value text} set (path items that are numbers index
    arrays, e.g. ``plates.3.E``) and ``remove`` (dotted paths) deleted, written to ``tmp_path/name``."""
    doc = tomlkit.parse(Path(source).read_text())

    def walk(path):
        *keys, last = path.split(".")
        node = doc
        for k in keys:
            node = node[int(k)] if k.isdigit() else node[k]
        return node, int(last) if last.isdigit() else last

    for path in remove:
        node, last = walk(path)
        del node[last]
    for path, value in (changes or {}).items():
        node, last = walk(path)
        node[last] = tomlkit.parse(f"x = {value}")["x"]
    out = Path(tmp_path) / name
    out.write_text(tomlkit.dumps(doc))
    return out


def plate_box(tmp_path, a_mm: float, b_mm: float, t_mm: float, body: str = "", mesh_mm: float = 10.0,
              material: str = 'E = "70 GPa"\nnu = 0.33\nrho = "2700 kg/m^3"', name: str = "box.toml",
              axes=((1, 0, 0), (0, 1, 0))) -> Path:
    """A box of one plate a x b along the unit ``axes`` (u, v; default the x-y plane), material ``al``, with
    ``body`` appended (ribs, supports)."""
    u, v = (", ".join(f'"{side * c:g} mm"' for c in axis) for side, axis in ((a_mm, axes[0]), (b_mm, axes[1])))
    text = (f'[box]\nname = "plate"\nmesh_size = "{mesh_mm} mm"\n\n[materials.al]\n{material}\n\n'
            f'[[plates]]\nname = "p"\norigin = ["0 mm", "0 mm", "0 mm"]\nu = [{u}]\n'
            f'v = [{v}]\nthickness = "{t_mm} mm"\nmaterial = "al"\n\n{body}')
    out = Path(tmp_path) / name
    out.write_text(text)
    return out


def supports(plate: str, kind: str, edges=("u0", "u1", "v0", "v1")) -> str:
    return "".join(f'[[supports]]\nplate = "{plate}"\nedge = "{e}"\ntype = "{kind}"\n\n' for e in edges)
