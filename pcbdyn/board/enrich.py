"""The enriched board.toml: the original file, unchanged, followed by a commented block declaring
the effects a diagnosis found (issue 7), so that ``pcbdyn build`` of the new file gives the
diagnosed model.

An effect is a dict (the shape of ``pcbdyn.diagnosis.Candidate`` kind/name/at/geometry + a value)::

    {"type": "point_mass" | "point_inertia" | "ground_spring" | "edge_stiffness" | "line_mass"
             | "stiffener" | "region_stiffness",
     "name": str, "value": float (SI: kg, kg m^2, N/m, N m/rad/m, kg, N m^2, or the relative
     stiffness change s of a region, whose stiffness factor is 1 + s),
     "at": (x, y) [m], "segment": [[x, y], [x, y]] (edge_stiffness, line_mass),
     "path": [[x, y], ...] (stiffener), "polygon": [[x, y], ...] (region_stiffness)}

A point_mass and a point_inertia at the same point become one ``[[masses]]`` entry.
"""

from __future__ import annotations

import datetime as _dt
import re
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from .spec import BoardError, load_board, read_toml

TYPES = ("point_mass", "point_inertia", "ground_spring", "edge_stiffness", "line_mass", "stiffener",
         "region_stiffness")
_GEOMETRY = {"edge_stiffness": "segment", "line_mass": "segment", "stiffener": "path", "region_stiffness": "polygon"}


def enriched_path(board_toml) -> Path:
    p = Path(board_toml)
    return p.with_name(f"{p.stem}.diagnosed{p.suffix}")


def _num(v: float) -> str:
    return f"{float(v):.12g}"


def _mm(v: float) -> str:
    return f'"{_num(1e3 * v)} mm"'


def _point(p) -> str:
    return f"[{_mm(p[0])}, {_mm(p[1])}]"


def _points(ps) -> str:
    return "[" + ", ".join(_point(p) for p in ps) + "]"


def _str(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


class _Names:
    """Entry names usable in parameter targets (no '.'), unique per array."""

    def __init__(self, data: dict):
        self.used = {key: {str(e.get("name", "")) for e in data.get(key, []) if isinstance(e, dict)}
                     for key in ("fixtures", "masses", "line_masses", "stiffeners", "regions")}

    def __call__(self, key: str, name: str) -> str:
        base = re.sub(r"[^A-Za-z0-9_-]+", "_", name).strip("_") or key
        out, k = base, 2
        while out in self.used[key]:
            out, k = f"{base}_{k}", k + 1
        self.used[key].add(out)
        return out


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


def effect_block(effects, data: dict, date: str | None = None, source: str = "pcbdyn diagnose") -> str:
    """The TOML text declaring ``effects`` after a board whose parsed content is ``data``."""
    for i, e in enumerate(effects):
        _check(e, i)
    names = _Names(data)
    date = date or _dt.date.today().isoformat()
    kinds = ", ".join(f"{e['type']} {e['name']}" for e in effects) or "none"
    out = ["\n# ---------------------------------------------------------------------------",
           f"# effects found by {source} on {date}: {kinds}",
           "# (each entry below was added to the original board above; values as estimated)"]
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
    for at, m, J, who in masses:
        out += ["", f"# point mass ({' + '.join(who)}): {_num(m * 1e3)} g, rotary inertia {_num(J)} kg*m^2 "
                    "about x and y", "[[masses]]", f"name = {_str(names('masses', who[0]))}", f"at = {_point(at)}",
                f'mass = "{_num(m * 1e3)} g"']
        if J:
            out.append(f'inertia = "{_num(J)} kg*m^2"')
    for e in effects:
        typ, v, name = e["type"], float(e["value"]), str(e["name"])
        if typ == "ground_spring":
            out += ["", f"# {name}: spring to ground in z, {_num(v)} N/m", "[[fixtures]]",
                    f"name = {_str(names('fixtures', name))}", 'type = "point_spring"', f"at = {_point(e['at'])}",
                    f'k = "{_num(v)} N/m"']
        elif typ == "edge_stiffness":
            a, b = e["segment"]
            out += ["", f"# {name}: rotational stiffness about the segment, {_num(v)} N*m/rad/m", "[[fixtures]]",
                    f"name = {_str(names('fixtures', name))}", 'type = "edge_spring"', f"from = {_point(a)}",
                    f"to = {_point(b)}", f'k_rot = "{_num(v)} N*m/rad/m"']
        elif typ == "line_mass":
            a, b = e["segment"]
            out += ["", f"# {name}: {_num(v * 1e3)} g spread along the segment", "[[line_masses]]",
                    f"name = {_str(names('line_masses', name))}", f"from = {_point(a)}", f"to = {_point(b)}",
                    f'mass = "{_num(v * 1e3)} g"']
        elif typ == "stiffener":
            out += ["", f"# {name}: rib of bending stiffness {_num(v)} N*m^2 (aluminium, 4 mm high)",
                    "[[stiffeners]]", f"name = {_str(names('stiffeners', name))}", f"path = {_points(e['path'])}",
                    f'EI = "{_num(v)} N*m^2"']
        elif typ == "region_stiffness":
            out += ["", f"# {name}: stiffness changed by {_num(100 * v)} %", "[[regions]]",
                    f"name = {_str(names('regions', name))}", f"polygon = {_points(e['polygon'])}",
                    f"stiffness_factor = {_num(1.0 + v)}"]
    return "\n".join(out) + "\n"


def write_enriched(original_path, effects, out_path=None, date: str | None = None) -> Path:
    """Write ``original_path``'s text unchanged followed by the declarations of ``effects`` to
    ``out_path`` (default ``<stem>.diagnosed.toml`` beside the original), atomically; the result
    is loaded with ``load_board`` before it replaces ``out_path``. Returns the path written."""
    src = Path(original_path)
    text, data = read_toml(src)
    dst = Path(out_path) if out_path is not None else enriched_path(src)
    body = text if text.endswith("\n") or not text else text + "\n"
    body += effect_block(list(effects), data, date)
    with atomic_path(dst) as tmp:
        tmp.write_text(body)
        try:
            load_board(tmp)  # beside the output: parts' packages are looked up from its folder
        except BoardError as exc:
            raise BoardError(f"{dst.name}: the enriched board does not load ({exc}); nothing was written") from None
    return dst

