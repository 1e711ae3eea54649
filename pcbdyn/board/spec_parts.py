"""board.toml readers of the parts (``[[components]]``): package from the library, size, mass, part
model (thesis section 7.2), region properties; footprints on the board and not overlapping."""

from __future__ import annotations

import difflib

from ..inputs import MAX_NAME
from ..components.library import MODELS, LibraryError, Package, available, find_package
from .entries import Component
from .geometry import polys_overlap


def read_component(r, c, where, board) -> Component:
    r.table(c, where, ["ref", "package", "at", "rotation", "model", "thickness", "size", "height", "mass", "E",
                       "rho"], required=["ref", "at"])
    ref = r.name("components", c, 0, where)
    if board.component(ref) is not None:
        r.fail(f"{where}.ref", f"'{ref}' is used by another part; references must be unique")
    pkg: Package | None = None
    if "package" in c:
        r.text(c["package"], f"{where}.package", MAX_NAME)
        try:
            pkg = find_package(c["package"], board.path.parent)
        except LibraryError as exc:
            r.fail(f"{where}.package", str(exc))
        if pkg is None:
            names = available(board.path.parent)
            close = difflib.get_close_matches(str(c["package"]), names, n=1)
            hint = f"did you mean '{close[0]}'?" if close else f"known: {', '.join(names)}"
            r.fail(f"{where}.package", f"unknown package '{c['package']}' ({hint}); or give size and mass "
                                       "instead of package")
    for key in ("size", "mass"):
        if pkg is None and key not in c and not (key == "mass" and "rho" in c):
            r.fail(f"{where}.{key}", f"missing: a part without a package needs size and mass; add {key} = ...")
    if "rho" in c and "mass" in c:
        r.fail(f"{where}.rho", "give mass or rho, not both (a region density sets the part's mass)")
    if "size" in c:
        if not (isinstance(c["size"], list) and len(c["size"]) == 2):
            r.fail(f"{where}.size", "must be two lengths, e.g. [\"40 mm\", \"40 mm\"]")
        size = tuple(r.q(s, "mm", f"{where}.size[{i}]", positive=True) for i, s in enumerate(c["size"]))
    else:
        size = pkg.size
    mass = r.q(c["mass"], "g", f"{where}.mass", positive=True) if "mass" in c else (pkg.mass if pkg else 0.0)
    height = r.q(c["height"], "mm", f"{where}.height", positive=True) if "height" in c else (
        pkg.height if pkg else 0.0)
    model = r.choice(c.get("model", pkg.default_model if pkg else "lumped"), f"{where}.model", MODELS, "part model")
    thickness = None
    if model == "equivalent_thickness":
        if "thickness" in c:
            thickness = r.q(c["thickness"], "mm", f"{where}.thickness", positive=True)
        elif pkg is not None:
            thickness = pkg.equivalent_thickness
        else:
            r.fail(f"{where}.thickness", "missing: the equivalent_thickness model needs thickness = \"3.5 mm\" "
                                         "(or a package that gives one)")
    elif "thickness" in c:
        r.fail(f"{where}.thickness", f"only the equivalent_thickness model uses a thickness (model is '{model}')")
    E = r.q(c["E"], "Pa", f"{where}.E", positive=True) if "E" in c else None
    rho = r.q(c["rho"], "kg/m^3", f"{where}.rho", positive=True) if "rho" in c else None
    if E is not None and model != "smeared_local":
        r.fail(f"{where}.E", f"only the smeared_local model uses a region E (model is '{model}')")
    if rho is not None and model not in ("smeared_local", "equivalent_thickness"):
        r.fail(f"{where}.rho", f"only smeared_local and equivalent_thickness use a region rho (model is '{model}')")
    if E is not None and board.isotropic is None:
        r.fail(f"{where}.E", "a region E needs a board given by material, not by stackup")
    if rho is not None:  # the region density sets the part's mass (board + part = rho t S)
        t_region = thickness if model == "equivalent_thickness" else board.plate.t
        mass = (rho * t_region - board.plate.mass_per_area()) * size[0] * size[1]
        if mass < 0:
            r.fail(f"{where}.rho", f"region density {c['rho']!r} carries less mass than the bare board it "
                                   "replaces; raise it or use mass = ...")
    comp = Component(ref, r.point(c["at"], f"{where}.at"),
                     r.q(c.get("rotation", "0 deg"), "deg", f"{where}.rotation"), size, height, mass, model,
                     thickness, E, rho, pkg.name if pkg else None)
    if not board.outline.contains(comp.corners()).all() or not board.outline.contains(comp.at)[0]:
        r.fail(f"{where}.at", f"part {ref} ({size[0] * 1e3:g} x {size[1] * 1e3:g} mm at "
                              f"{comp.at[0] * 1e3:g}, {comp.at[1] * 1e3:g} mm) does not lie on the board; move it "
                              "so its whole footprint is inside the outline")
    for h in board.outline.holes:
        if polys_overlap(comp.corners(), h):
            r.fail(f"{where}.at", f"part {ref} overlaps a hole in the board; move it")
    return comp


def check_overlaps(r, board):
    """No two footprints overlap (touching is allowed); candidate pairs from a spatial index of their
    bounding boxes, so many parts cost n log n."""
    from shapely import STRtree, box

    cs = board.components
    corners = [c.corners() for c in cs]
    boxes = [box(*k.min(axis=0), *k.max(axis=0)) for k in corners]
    pairs = STRtree(boxes).query(boxes, predicate="intersects").T if boxes else []
    for i, j in sorted((int(a), int(b)) for a, b in pairs if a > b):
        if polys_overlap(corners[i], corners[j]):
            r.fail(f"components[{i}].at", f"part {cs[i].ref} overlaps part {cs[j].ref}; move one of them "
                                          "(footprints may touch but not overlap)")
