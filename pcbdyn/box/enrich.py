"""The enriched box.toml: the original file, its comments and layout kept, with the effects a diagnosis
found declared as box entries (tomlkit), so that ``pcbdyn build`` of the new file gives the diagnosed
model: a point mass becomes a ``[[masses]]`` entry on its plate (at its lengths along u and v), a plate
stiffer or softer as a whole that plate's own ``E`` (the declared one times 1 + s), a stiffener a
``[[ribs]]`` entry (:func:`_rib`). A box has no entry for a spring to ground: such effects are written as
comments that say where and how stiff.

An effect is a dict as :func:`pcbdyn.report.diagnosis_report.enriched_effects` makes them: type, name,
value (SI), at (x, y, z) [m] and plate; a stiffener's path [m], section height [m], material and the
normal of the side it stands on.
"""

from __future__ import annotations


import numpy as np
import tomlkit

from .. import targets
from ..inputs import entry_name, new_entry_name
from .entries import BoxError


def _name(doc, base: str, collection: str = "masses") -> str:
    used = {entry_name(collection, e, i) for i, e in enumerate(doc.get(collection, []))}
    return new_entry_name(base, used, collection[:-1])


def _rib(doc, plate, e) -> tomlkit.items.Table:
    """A stiffener found as a ``[[ribs]]`` entry: its line in lengths along the plate's u and v, and the
    diagnosis's section (its material, its height h and the width b = 12 EI / (E h^3) its stiffness EI
    gives), on the side of the plate its ``normal`` points to, where the diagnosis placed it."""
    m, h = e["material"], float(e["height"])
    ends = plate.coordinates(np.asarray(e["path"], float))[:, :2] * plate.lengths
    width = 12.0 * float(e["value"]) / (m["E_Pa"] * h**3)
    side = "+n" if plate.normal @ np.asarray(e["normal"], float) > 0 else "-n"
    entry = tomlkit.table()
    entry.update({"name": _name(doc, str(e["name"]), "ribs"), "plate": plate.name,
                  "from": [targets.quantity(v, "mm") for v in ends[0]], "to": [targets.quantity(v, "mm") for v in ends[-1]],
                  "height": targets.quantity(h, "mm"), "width": targets.quantity(width, "mm"), "side": side})
    material = tomlkit.inline_table()
    material.update({"E": targets.quantity(m["E_Pa"], "GPa"), "nu": m["nu"],
                     "rho": targets.quantity(m["rho_kg_m3"], "kg/m^3")})
    entry["material"] = material
    entry.comment(f"found by pcbdyn diagnose ({e['name']})")
    return entry


def enriched_text(box, text: str, effects) -> str:
    """``text`` (box.toml of ``box``) with ``effects`` declared."""
    doc = tomlkit.parse(text)
    for e in effects:
        plate = box.plate(e.get("plate"))
        if plate is None:
            raise BoxError(f"effect {e.get('name')}: names no plate of {box.path.name}")
        if e["type"] == "point_mass":
            s, t, _ = plate.coordinates(np.asarray(e["at"], float))[0]
            a, b = s * plate.lengths[0], t * plate.lengths[1]
            entry = tomlkit.table()
            entry.update({"name": _name(doc, str(e["name"])), "plate": plate.name,
                          "at": [targets.quantity(v, "mm") for v in (a, b)],
                          "mass": targets.formatted(targets.KINDS["masses", "mass"], float(e["value"]))})
            entry.comment(f"found by pcbdyn diagnose ({e['name']})")
            doc.setdefault("masses", tomlkit.aot()).append(entry)
        elif e["type"] == "stiffener" and {"path", "material", "normal"} <= e.keys():
            doc.setdefault("ribs", tomlkit.aot()).append(_rib(doc, plate, e))
        elif e["type"] == "region_stiffness":
            i = next(k for k, p in enumerate(doc["plates"]) if entry_name("plates", p, k) == plate.name)
            factor = 1.0 + float(e["value"])
            E = plate.material.E
            doc["plates"][i]["E"] = ([targets.quantity(v * factor, "GPa") for v in E] if isinstance(E, tuple)
                                     else targets.quantity(E * factor, "GPa"))
        else:
            doc.add(tomlkit.comment(f"pcbdyn diagnose found a {e['type']} of {float(e['value']):.6g} (SI) at "
                                    f"{np.round(np.asarray(e['at']) * 1e3, 2).tolist()} mm on plate {plate.name}; "
                                    "a box has no entry for it: model it by hand"))
    return tomlkit.dumps(doc)
