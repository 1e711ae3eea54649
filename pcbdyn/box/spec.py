"""box.toml readers, one per table: materials, plates, ribs, supports, joints, masses, configurations;
and the checks that need several tables (plates that meet, ribs and masses on their plates)."""

from __future__ import annotations

import numpy as np

from ..inputs import MAX_ENTRIES, MAX_NAME
from ..units import shown
from .entries import (EDGES, GEOM_TOL, RIB_SIDES, SUPPORT_TYPES, BoxMass, BoxMaterial, Configuration, Joint, Plate,
                      Rib, Support)
from .geometry import contacts, groups, nearest_edges

MATERIAL_EXAMPLE = 'material = { E = "70 GPa", nu = 0.33, rho = "2700 kg/m^3" }'


def read_modulus(r, value, where):
    """E as a quantity, or ["Eu", "Ev"] (orthotropic: along the plate's u and v)."""
    if isinstance(value, list):
        if len(value) != 2:
            r.fail(where, f"give one modulus or two [\"Eu\", \"Ev\"] (along the plate's u and v), got {value!r}")
        return tuple(r.q(v, "Pa", f"{where}[{i}]", positive=True) for i, v in enumerate(value))
    return r.q(value, "Pa", where, positive=True)


def read_material(r, m, where) -> BoxMaterial:
    r.table(m, where, ["E", "nu", "rho"], required=["E", "nu", "rho"])
    return BoxMaterial(read_modulus(r, m["E"], f"{where}.E"), r.number(m["nu"], f"{where}.nu", -1.0, 0.5),
                       r.q(m["rho"], "kg/m^3", f"{where}.rho", positive=True))


def read_materials(r, data) -> dict:
    table = data.get("materials", {})
    if not isinstance(table, dict):
        r.fail("materials", "must be tables [materials.<name>] with E, nu and rho")
    if len(table) > MAX_ENTRIES:
        r.fail("materials", f"has {len(table):,} materials, more than the {MAX_ENTRIES:,} pcbdyn reads")
    return {r.text(k, f"materials.{k[:MAX_NAME]}", MAX_NAME): read_material(r, v, f"materials.{k}")
            for k, v in table.items()}


def material_of(r, value, where, materials) -> BoxMaterial:
    """A material given by name (a [materials.<name>] table) or inline."""
    if isinstance(value, dict):
        return read_material(r, value, where)
    if isinstance(value, str) and value in materials:
        return materials[value]
    known = ", ".join(materials) or "none defined"
    name = value if isinstance(value, str) and len(value) <= MAX_NAME else "<name>"
    r.fail(where, f"unknown material {shown(value)} (materials: {known}); add a [materials.{name}] table or write "
                  f"{MATERIAL_EXAMPLE}")


def read_plate(r, p, where, name, materials) -> Plate:
    r.table(p, where, ["name", "origin", "u", "v", "thickness", "material", "E", "rho"],
            required=["origin", "u", "v", "thickness", "material"])
    origin, u, v = (np.array(r.point(p[k], f"{where}.{k}", 3)) for k in ("origin", "u", "v"))
    for key, vec in (("u", u), ("v", v)):
        if np.linalg.norm(vec) < GEOM_TOL:
            r.fail(f"{where}.{key}", "has zero length; give the side of the plate as a vector")
    if np.linalg.norm(np.cross(u, v)) < 1e-6 * np.linalg.norm(u) * np.linalg.norm(v):
        r.fail(f"{where}.v", "is parallel to u: a plate needs two sides that are not parallel")
    mat = material_of(r, p["material"], f"{where}.material", materials)
    E = read_modulus(r, p["E"], f"{where}.E") if "E" in p else mat.E
    rho = r.q(p["rho"], "kg/m^3", f"{where}.rho", positive=True) if "rho" in p else mat.rho
    t = r.q(p["thickness"], "mm", f"{where}.thickness", positive=True)
    if t >= min(np.linalg.norm(u), np.linalg.norm(v)):
        r.fail(f"{where}.thickness", f"{t * 1e3:g} mm is as thick as the plate is wide; a plate is thin: check the "
                                     "units")
    return Plate(name, origin, u, v, t, BoxMaterial(E, mat.nu, rho), mat)


def _on_plate(r, plate, ab, where) -> tuple:
    la, lb = plate.lengths
    a, b = ab
    if not (-GEOM_TOL <= a <= la + GEOM_TOL and -GEOM_TOL <= b <= lb + GEOM_TOL):
        r.fail(where, f"({a * 1e3:g}, {b * 1e3:g}) mm is off plate '{plate.name}' (0 to {la * 1e3:g} mm along u, 0 to "
                      f"{lb * 1e3:g} mm along v); give lengths along u and v from the plate's origin that lie on it")
    return float(np.clip(a, 0.0, la)), float(np.clip(b, 0.0, lb))


def _plate(r, plates, value, where):
    plate = next((p for p in plates if p.name == value), None)
    if plate is None:
        r.fail(where, f"no plate is called {shown(value)} (plates: {', '.join(p.name for p in plates)}); name one of them")
    return plate


def read_rib(r, e, where, name, plates, materials) -> Rib:
    r.table(e, where, ["name", "plate", "from", "to", "height", "width", "side", "material"],
            required=["plate", "from", "to", "height", "width"])
    plate = _plate(r, plates, e["plate"], f"{where}.plate")
    a = _on_plate(r, plate, r.point(e["from"], f"{where}.from"), f"{where}.from")
    b = _on_plate(r, plate, r.point(e["to"], f"{where}.to"), f"{where}.to")
    if np.linalg.norm(plate.point(*a) - plate.point(*b)) < 1e-4:
        r.fail(f"{where}.to", "is where the rib starts; a rib needs a length")
    side = r.choice(e.get("side", "+n"), f"{where}.side", RIB_SIDES, "rib side",
                    {"+n": "the rib stands on the side n = u x v points to", "-n": "on the other side"})
    mat = material_of(r, e["material"], f"{where}.material", materials) if "material" in e else plate.declared
    if mat.orthotropic:
        r.fail(f"{where}.material", f"a rib needs an isotropic material (one E), and plate '{plate.name}' has an "
                                    "orthotropic one; give the rib its own material")
    return Rib(name, plate.name, a, b, r.q(e["height"], "mm", f"{where}.height", positive=True),
               r.q(e["width"], "mm", f"{where}.width", positive=True), side, mat)


def read_support(r, e, where, plates) -> Support:
    r.table(e, where, ["plate", "edge", "type"], required=["plate", "edge"])
    plate = _plate(r, plates, e["plate"], f"{where}.plate")
    edge = r.choice(e["edge"], f"{where}.edge", EDGES, "plate edge", {k: f"{a} = {v:g}" for k, (a, v) in EDGES.items()})
    typ = r.choice(e.get("type", "clamped"), f"{where}.type", SUPPORT_TYPES, "support type")
    return Support(plate.name, edge, typ)


def read_mass(r, e, where, name, plates) -> BoxMass:
    r.table(e, where, ["name", "plate", "at", "mass"], required=["plate", "at", "mass"])
    plate = _plate(r, plates, e["plate"], f"{where}.plate")
    at = _on_plate(r, plate, r.point(e["at"], f"{where}.at"), f"{where}.at")
    return BoxMass(name, plate.name, at, r.q(e["mass"], "g", f"{where}.mass", nonneg=True))


def read_configuration(r, e, where, plates) -> Configuration:
    r.table(e, where, ["name", "masses"], required=["name"])
    ms = r.list(e, "masses", f"{where}.masses")
    masses = [read_mass(r, m, f"{where}.masses[{j}]", r.name("masses", m, j, f"{where}.masses[{j}]"),
                        plates) for j, m in enumerate(ms)]
    r.unique([m.name for m in masses], f"{where}.masses", "name")
    return Configuration(r.name("configurations", e, 0, where), masses)


def read_joint(r, e, where, name, found) -> Joint:
    r.table(e, where, ["name", "plates", "k_rot"], required=["plates", "k_rot"])
    pair = e["plates"]
    if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(p, str) for p in pair)):
        r.fail(f"{where}.plates", f"must name two plates, e.g. [\"upper\", \"left\"], got {shown(pair)}")
    if not any(set(c.plates) == set(pair) for c in found):
        r.fail(f"{where}.plates", f"plates {pair[0]!r} and {pair[1]!r} share no edge; a joint is the edge two plates "
                                  "share (without an entry it is rigid)")
    return Joint(name, tuple(pair), r.q(e["k_rot"], "N*m/rad/m", f"{where}.k_rot", positive=True))


def check_plates(r, plates, supports) -> list:
    """The plates' contacts; a clear error for a plate (or group of plates) that meets no other and
    is not held, naming the gap to its nearest neighbour."""
    found = contacts(plates)
    parts = groups(plates, found)
    held = {s.plate for s in supports}
    loose = [g for g in parts if not (g & held)] if held else (parts if len(parts) > 1 else [])
    if loose:
        g = min(loose, key=len)
        near = [(*nearest_edges(a, b), i, b) for i, a in enumerate(plates) if a.name in g for b in plates
                if b.name not in g]
        if not near:
            r.fail("supports", "no plate of the box is held; add [[supports]] or leave the box free (no supports)")
        gap, ea, eb, i, pb = min(near, key=lambda t: t[0])
        pa = plates[i]
        r.fail(f"plates[{i}]", f"plate '{pa.name}' does not meet the rest of the box: the nearest edges, "
                               f"{pa.name}.{ea} and {pb.name}.{eb}, are {gap * 1e3:.4g} mm apart; move its origin or "
                               "change u, v so that the plates share the edge (or hold it with a [[supports]] entry)")
    return found
