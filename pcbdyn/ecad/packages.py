"""The map from KiCad footprint names to part families (map.toml).

    [footprints]                      # "Library:Footprint", * and ? wildcards; first match wins
    "Package_QFP:LQFP-64_*" = "CQFP"  # a family of the component library (its mass, model ...)
    "Capacitor_THT:CP_Radial_*" = { mass = "2 g", height = "12 mm" }   # a lumped part
    "Package_BGA:*" = { package = "PGA", mass = "4 g" }                # a family, own mass
    "Fiducial:*" = "ignore"           # known, massless: neither placed nor listed as unmapped
    "MyLib:Spacer_M3" = "standoff"    # a mounting hole (MountingHole:* are recognised anyway)

    [materials]                       # stack-up dielectrics pcbdyn does not name
    "Rogers 4350B" = { E = "19 GPa", nu = 0.2, rho = "1860 kg/m^3" }

A table may give package, mass, height, model and thickness (as board.toml's [[components]]);
the footprint's own courtyard gives the part's size. Footprints that match no entry are kept
out of the board and listed with their count: a part's mass is never guessed.
"""

from __future__ import annotations

import fnmatch
from dataclasses import dataclass
from pathlib import Path

from ..board.spec import read_material
from ..inputs import read_toml
from .kicad import KicadError

PART_KEYS = ("package", "mass", "height", "model", "thickness")
KEYWORDS = ("ignore", "standoff")


@dataclass
class PackageMap:
    path: Path
    entries: list  # [(pattern, "ignore" | "standoff" | {component keys})]
    materials: dict

    def lookup(self, lib_id: str):
        """The entry of the first pattern matching ``lib_id``, or None."""
        for pattern, value in self.entries:
            if fnmatch.fnmatchcase(lib_id, pattern):
                return value
        return None


def read_map(path) -> PackageMap:
    """The footprint map of ``path``, every entry checked (family names, quantities with their units, part
    models, materials); a KicadError names the file, the entry and the fix."""
    from ..components.library import MODELS, check_family
    from ..inputs import MAX_NAME, Reader

    path = Path(path)
    if not path.is_file():
        raise KicadError(f"{path}: no such file; give the footprint map with --packages map.toml")
    data = read_toml(path, KicadError)[1]
    r = Reader(path, KicadError)
    r.table(data, "top level", ["footprints", "materials"])
    entries = []
    for pattern, value in r.table(data.get("footprints", {}), "footprints").items():
        where = f"footprints.\"{pattern[:MAX_NAME]}\""
        r.text(pattern, where, 200)
        if isinstance(value, str) and value in KEYWORDS:
            entries.append((pattern, value))
            continue
        table = {"package": value} if isinstance(value, str) else value
        if not isinstance(table, dict):
            r.fail(where, "must be a family name, \"ignore\", \"standoff\" or a table { package = ... }")
        r.table(table, where, list(PART_KEYS))
        if "package" not in table and "mass" not in table:
            r.fail(where, "give a package (library family) or a mass, e.g. { mass = \"2 g\" }")
        if "package" in table and (why := check_family(table["package"])) is not None:
            r.fail(f"{where}.package", why)
        for key, unit, positive in (("mass", "g", True), ("height", "mm", False), ("thickness", "mm", True)):
            if key in table:
                r.q(table[key], unit, f"{where}.{key}", positive=positive, nonneg=True)
        if "model" in table:
            r.choice(table["model"], f"{where}.model", MODELS, "part model")
        entries.append((pattern, dict(table)))
    materials = r.table(data.get("materials", {}), "materials")
    for name, m in materials.items():
        where = f"materials.\"{name[:MAX_NAME]}\""
        if isinstance(m, dict):
            read_material(r, m, where)
        elif not isinstance(m, str):
            r.fail(where, "give a pcbdyn material name or { E, nu, rho }")
    return PackageMap(path, entries, materials)
