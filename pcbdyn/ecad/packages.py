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
import tomllib
from dataclasses import dataclass
from pathlib import Path

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
    path = Path(path)
    if not path.is_file():
        raise KicadError(f"{path}: no such file; give the footprint map with --packages map.toml")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise KicadError(f"{path.name}: not valid TOML: {exc}; fix the syntax at that line") from None
    unknown = set(data) - {"footprints", "materials"}
    if unknown:
        raise KicadError(f"{path.name}: unknown table(s) {', '.join(sorted(unknown))}; use [footprints] and [materials]")
    entries = []
    for pattern, value in data.get("footprints", {}).items():
        where = f"{path.name}: footprints.\"{pattern}\""
        if isinstance(value, str):
            entries.append((pattern, value if value in KEYWORDS else {"package": value}))
        elif isinstance(value, dict):
            bad = set(value) - set(PART_KEYS)
            if bad:
                raise KicadError(f"{where}: unknown key(s) {', '.join(sorted(bad))}; use {', '.join(PART_KEYS)}")
            if "package" not in value and "mass" not in value:
                raise KicadError(f"{where}: give a package (library family) or a mass, e.g. {{ mass = \"2 g\" }}")
            entries.append((pattern, dict(value)))
        else:
            raise KicadError(f"{where}: must be a family name, \"ignore\", \"standoff\" or a table {{ package = ... }}")
    materials = data.get("materials", {})
    for name, m in materials.items():
        if not (isinstance(m, (str, dict))):
            raise KicadError(f"{path.name}: materials.\"{name}\": give a pcbdyn material name or {{ E, nu, rho }}")
    return PackageMap(path, entries, materials)
