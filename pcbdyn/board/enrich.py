"""The enriched board.toml: the original file, its comments and layout kept, with the effects a
diagnosis found declared as board entries (tomlkit), so that ``pcbdyn build`` of the new file gives the
diagnosed model.

An effect is a dict (the shape of ``pcbdyn.diagnosis.Candidate`` kind/name/at/geometry + a value)::

    {"type": "point_mass" | "point_inertia" | "ground_spring" | "edge_stiffness" | "line_mass"
             | "stiffener" | "region_stiffness" | "region_mass",
     "name": str, "value": float (SI: kg, kg m^2, N/m, N m/rad/m, kg, N m^2, or the relative
     stiffness change s of a region, whose stiffness factor is 1 + s, or a region's mass in kg),
     "at": (x, y) [m], "segment": [[x, y], [x, y]] (edge_stiffness, line_mass),
     "path": [[x, y], ...] (stiffener; "height" [m]: its section's, default aluminium 4 mm),
     "polygon": [[x, y], ...] (region_stiffness, region_mass)}

A point_mass and a point_inertia at the same point become one ``[[masses]]`` entry.
"""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

import numpy as np
import shapely
import tomlkit

from .. import targets
from ..inputs import entry_name, new_entry_name
from .entries import MIN_SEGMENT, BoardError, RibSection

TYPES = ("point_mass", "point_inertia", "ground_spring", "edge_stiffness", "line_mass", "stiffener",
         "region_stiffness", "region_mass")
_GEOMETRY = {"edge_stiffness": "segment", "line_mass": "segment", "stiffener": "path", "region_stiffness": "polygon",
             "region_mass": "polygon"}


def enriched_path(board_toml) -> Path:
    p = Path(board_toml)
    return p.with_name(f"{p.stem}.diagnosed{p.suffix}")


def _point(p) -> list:
    return [targets.quantity(v, "mm") for v in p[:2]]


def _check(e: dict, i: int) -> None:
    where = f"effects[{i}]"
    if not isinstance(e, dict):
        raise BoardError(f"{where}: must be a dict with type, name, value and geometry")
    typ = e.get("type")
    if typ not in TYPES:
        raise BoardError(f"{where}.type: unknown effect type {typ!r}; use one of {', '.join(TYPES)}")
    for key in ("name", "value") + (("at",) if typ not in _GEOMETRY else (_GEOMETRY[typ],)):
        if key not in e:
            raise BoardError(f"{where}.{key}: missing for a {typ} effect")
    if not np.isfinite(float(e["value"])):
        raise BoardError(f"{where}.value: must be finite, got {e['value']!r}")


class _Names:
    """Entry names usable in parameter targets (no '.'), unique per array of the document."""

    def __init__(self, doc):
        self.used = {key: {entry_name(key, e, i) for i, e in enumerate(doc.get(key, []))}
                     for key in ("fixtures", "masses", "line_masses", "stiffeners", "regions")}

    def __call__(self, key: str, name: str) -> str:
        return new_entry_name(name, self.used[key], key)


def _outline(polygon) -> np.ndarray:
    """``polygon`` (m, 2) without the corners closer than a board.toml polygon may have
    (:data:`.entries.MIN_SEGMENT`): a union of overlapping regions has repeated and collinear ones."""
    simple = shapely.Polygon(np.asarray(polygon, float)).simplify(MIN_SEGMENT)
    return np.asarray(simple.exterior.coords)[:-1]


def _entries(effects, names) -> list:
    """[(collection, note, {field: value})] declaring ``effects`` as board entries."""
    out = []
    masses: list = []  # [at, mass, inertia, [names]]
    for e in effects:
        if e["type"] in ("point_mass", "point_inertia"):
            at = np.asarray(e["at"], dtype=float)
            slot = next((m for m in masses if np.allclose(m[0], at, rtol=0.0, atol=1e-9)), None)
            if slot is None:
                slot = [at, 0.0, 0.0, []]
                masses.append(slot)
            slot[1 if e["type"] == "point_mass" else 2] += float(e["value"])
            slot[3].append(str(e["name"]))
    kind = targets.KINDS
    for at, m, J, who in masses:
        fields = {"name": names("masses", who[0]), "at": _point(at), "mass": targets.formatted(kind["masses", "mass"], m)}
        if J:
            fields["inertia"] = targets.formatted(kind["masses", "inertia"], J)
        out.append(("masses", f"point mass ({' + '.join(who)}), rotary inertia about x and y", fields))
    for e in effects:
        typ, v, name = e["type"], float(e["value"]), str(e["name"])
        if typ == "ground_spring":
            out.append(("fixtures", f"{name}: spring to ground in z", {
                "name": names("fixtures", name), "type": "point_spring", "at": _point(e["at"]),
                "k": targets.formatted(kind["fixtures", "k"], v)}))
        elif typ == "edge_stiffness":
            a, b = e["segment"]
            out.append(("fixtures", f"{name}: rotational stiffness about the segment", {
                "name": names("fixtures", name), "type": "edge_spring", "from": _point(a), "to": _point(b),
                "k_rot": targets.formatted(kind["fixtures", "k_rot"], v)}))
        elif typ == "line_mass":
            a, b = e["segment"]
            out.append(("line_masses", f"{name}: mass spread along the segment", {
                "name": names("line_masses", name), "from": _point(a), "to": _point(b),
                "mass": targets.formatted(kind["line_masses", "mass"], v)}))
        elif typ == "stiffener":
            fields = {"name": names("stiffeners", name), "path": [_point(p) for p in e["path"]],
                      "EI": targets.formatted(kind["stiffeners", "EI"], v)}
            h = e.get("height", RibSection().h)
            if h != RibSection().h:
                fields["section"] = {"height": targets.quantity(h, "mm")}
            out.append(("stiffeners", f"{name}: rib (aluminium, {1e3 * h:.3g} mm high)", fields))
        elif typ == "region_stiffness":
            out.append(("regions", f"{name}: stiffness changed by {100 * v:.4g} %", {
                "name": names("regions", name), "polygon": [_point(p) for p in _outline(e["polygon"])],
                "stiffness_factor": targets.formatted(kind["regions", "stiffness_factor"], 1.0 + v)}))
        elif typ == "region_mass":
            out.append(("regions", f"{name}: mass spread over the region", {
                "name": names("regions", name), "polygon": [_point(p) for p in _outline(e["polygon"])],
                "mass": targets.formatted(kind["regions", "mass"], v)}))
    return out


def enriched_text(text: str, effects, date: str | None = None, source: str = "pcbdyn diagnose") -> str:
    """The board.toml ``text`` with ``effects`` declared as new entries, each with a comment saying where
    it came from; everything the user wrote is kept."""
    effects = list(effects)
    for i, e in enumerate(effects):
        _check(e, i)
    doc = tomlkit.parse(text)
    date = date or _dt.date.today().isoformat()
    for collection, note, fields in _entries(effects, _Names(doc)):
        targets.append_entry(doc, collection, fields, f"found by {source} on {date}: {note}")
    return tomlkit.dumps(doc)
