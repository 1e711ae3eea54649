"""The one grammar of parameter targets: ``<collection>.<name>.<attribute>`` (``components.U1.thickness``,
``fixtures.guide.k_rot``, ``ribs.left_v1.height``) or ``<table>.<attribute>`` (``board.E``).

A target names one quantity of a structure described in TOML (board.toml, box.toml). This module
knows, for every target kind, its display unit, whether it is a spring stiffness (updated on a log
scale: it spans decades), where its value sits in the TOML document and how it is written there; it
validates a ``[[parameters]]`` entry against a structure (which says what value a target has, or that
it has none) and writes updated values back into the user's file with its comments and layout kept
(tomlkit). Entry names follow one rule everywhere (:func:`pcbdyn.inputs.entry_name`; new ones:
:func:`pcbdyn.inputs.new_entry_name`): an entry without ``name`` (``ref`` for parts) is called after
its kind and position (``wedge_lock2``, ``m1``).
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass
from typing import Callable

import tomlkit

from .domain import StructureError
from .inputs import MAX_NAME, NAME_FIELD, Reader, entry_name
from .units import UnitError, from_si, registry, shown, to_si


class TargetError(StructureError):
    """A target or a parameter entry that cannot be used; the message names the field and the fix."""


@dataclass(frozen=True)
class Kind:
    """One target kind: ``collection`` (an array of tables such as ``components``, or a table such as
    ``board``), ``attribute``, the display ``unit``, ``log`` (a stiffness updated on a log scale),
    ``path`` (keys below the entry, default the attribute), ``number`` (written as a bare number:
    dimensionless factors), ``excludes`` (keys the value replaces in the entry, e.g. a region density
    replaces the part's mass) and what it means (``what``)."""

    collection: str
    attribute: str
    unit: str
    what: str
    log: bool = False
    path: tuple = ()
    number: bool = False
    excludes: tuple = ()

    @property
    def keys(self) -> tuple:
        return self.path or (self.attribute,)

    @property
    def pattern(self) -> str:
        return f"{self.collection}.{self.attribute}" if self.collection in TABLES else \
            f"{self.collection}.<{NAME_FIELD.get(self.collection, 'name')}>.{self.attribute}"


#: collections that are one table (targets ``<table>.<attribute>``); the others are arrays of tables
TABLES = ("board",)
#: collections whose entries are structures of their own: ``<collection>.<name>.<target of the entry>``
#: (``cards.card1.components.U1.thickness``: a card's board.toml target, in a box.toml)
NESTED = ("cards",)

KINDS = {(k.collection, k.attribute): k for k in (
    Kind("board", "E", "Pa", "Young's modulus of the board", path=("material", "E")),
    Kind("board", "rho", "kg/m^3", "density of the board", path=("material", "rho")),
    Kind("board", "thickness", "mm", "thickness of the board"),
    Kind("board", "transverse_shear", "1", "factor on every shell's transverse shear stiffness", number=True),
    Kind("components", "thickness", "mm", "equivalent thickness of an equivalent_thickness part"),
    Kind("components", "mass", "g", "mass of a part", excludes=("rho",)),
    Kind("components", "E", "Pa", "region Young's modulus of a smeared_local part"),
    Kind("components", "rho", "kg/m^3", "region density of a smeared_local part", excludes=("mass",)),
    Kind("fixtures", "k_rot", "N*m/rad/m", "rotational stiffness of a wedge_lock or edge_spring", log=True),
    Kind("fixtures", "k", "N/m", "stiffness of a standoff or point_spring", log=True),
    Kind("masses", "mass", "g", "a point mass"),
    Kind("masses", "inertia", "kg*m^2", "rotary inertia of a point mass"),
    Kind("line_masses", "mass", "g", "mass of a line mass"),
    Kind("stiffeners", "EI", "N*m^2", "bending stiffness of a stiffener"),
    Kind("regions", "stiffness_factor", "1", "stiffness factor of a region", number=True),
    Kind("regions", "mass", "g", "mass spread over a region"),
    Kind("plates", "E", "Pa", "Young's modulus of an isotropic box plate (overrides its material's)"),
    Kind("plates", "rho", "kg/m^3", "density of a box plate (overrides its material's)"),
    Kind("plates", "thickness", "mm", "thickness of a box plate"),
    Kind("ribs", "height", "mm", "height of a box rib (a beam rib)"),
    Kind("ribs", "width", "mm", "width of a box rib (a beam rib)"),
    Kind("joints", "k_rot", "N*m/rad/m", "rotational stiffness of a box joint about its edge", log=True),
)}


@dataclass(frozen=True)
class Target:
    """A parsed target: ``collection``, entry ``name`` (None for a table) and ``attribute``; ``prefix``:
    the nested entry it belongs to (``cards.card1``), or None."""

    collection: str
    name: str | None
    attribute: str
    prefix: str | None = None

    def __str__(self) -> str:
        return ".".join(p for p in (self.prefix, self.collection, self.name, self.attribute) if p is not None)

    @property
    def kind(self) -> Kind:
        return KINDS[self.collection, self.attribute]


def entry(collection: str, name: str) -> str:
    """``<collection>.<name>`` (``components.U1``, ``fixtures.guide``): one entry of an array of tables.
    Its targets start with it, and a model names the element sets and the points the entry makes
    after it. With :func:`target` and :func:`member`, the one place these names are built."""
    return f"{collection}.{name}"


def member(entry_name: str, part: str) -> str:
    """``<entry>.<part>``: a quantity of the entry named ``entry_name`` (made by :func:`entry`), a target
    when the entry's collection has that kind (``masses.m1.mass``) and a quantity no parameter reaches
    otherwise (``configurations.drop.m1.mass``); or one of the entry's element sets
    (``line_masses.l1.3``, ``regions.r1.board``)."""
    return f"{entry_name}.{part}"


def prefix(collection: str, name: str) -> str:
    """``<collection>.<name>.``: what every name under the entry starts with (its quantities, sets and
    points); a structure nested in another (a card in a box, ``cards.card1.``) has its own names
    prefixed with it."""
    return member(entry(collection, name), "")


def target(collection: str, name: str | None, attribute: str) -> str:
    """The target ``<collection>.<name>.<attribute>`` (``components.U1.mass``), or ``<table>.<attribute>``
    (``board.E``) for a table, whose ``name`` is None. A kind :data:`KINDS` does not know is a
    TargetError: a misspelt target would make a quantity no parameter reaches."""
    if (collection, attribute) not in KINDS or (collection in TABLES) != (name is None):
        raise TargetError(f"{collection}.{name}.{attribute} is not a target; targets are {known()}")
    return str(Target(collection, name, attribute))


def known(collections=None) -> str:
    """The target patterns of ``collections`` (default all), for messages."""
    return ", ".join(k.pattern for k in KINDS.values() if collections is None or k.collection in collections)


def parse(text, collections=None) -> Target:
    """``text`` as a :class:`Target` of one of ``collections`` (default: any); TargetError otherwise,
    naming the target kinds there are."""
    parts = str(text).split(".")
    if len(parts) > 3 and parts[0] in NESTED and parts[1] and (collections is None or parts[0] in collections):
        inner = parse(".".join(parts[2:]))
        return Target(inner.collection, inner.name, inner.attribute, f"{parts[0]}.{parts[1]}")
    patterns = [k.pattern for k in KINDS.values() if collections is None or k.collection in collections]
    patterns += [f"{c}.<name>.<its target>" for c in NESTED if collections is not None and c in collections]
    table = len(parts) == 2 and parts[0] in TABLES
    if table or (len(parts) == 3 and parts[0] not in TABLES and all(parts)):
        if (parts[0], parts[-1]) in KINDS and (collections is None or parts[0] in collections):
            return Target(parts[0], None if table else parts[1], parts[-1])
    close = difflib.get_close_matches(f"{parts[0][:40]}.{parts[-1][:40]}", [p.replace(".<name>", "").replace(".<ref>", "")
                                                                  for p in patterns], n=1)
    hint = f"did you mean {close[0]}? " if close else ""
    raise TargetError(f"{shown(str(text))} is not a target of this structure; {hint}targets are {', '.join(patterns)}")


# ------------------------------------------------------------------------------------ parameters
@dataclass
class ParameterSpec:
    """A ``[[parameters]]`` entry: ``name``, ``targets`` (target strings sharing one value), ``bounds``
    (lower, upper) [SI], display ``unit``, ``log`` (a stiffness, updated on a log scale) and the
    targets' common starting ``value`` [SI]."""

    name: str
    targets: list
    bounds: tuple
    unit: str
    log: bool = False
    value: float = math.nan


def parameter_spec(entry: dict, where: str, value: Callable, file: str, collections=None) -> ParameterSpec:
    """The parameter of a ``[[parameters]]`` table ``entry`` (``where``: its place, e.g.
    ``parameters[2]``; ``file``: the file name for messages) on a structure whose ``value(target)``
    gives a target's current value [SI] or None when it has no such quantity. Targets must share one
    kind's unit and one starting value, which must lie within the bounds."""

    def fail(field, msg):
        raise TargetError(f"{file}: {where}{'.' + field if field else ''}: {msg}")

    r = Reader(file, TargetError)
    r.table(entry, where, ["name", "target", "bounds"], required=["name", "target", "bounds"])
    name = r.text(entry["name"], f"{where}.name", MAX_NAME)
    raw = entry["target"] if isinstance(entry["target"], list) else [entry["target"]]
    if not raw:
        fail("target", "is empty; give one target or a list of targets that share the value")
    for k, t in enumerate(raw):
        r.text(t, f"{where}.target" + (f"[{k}]" if isinstance(entry["target"], list) else ""), 3 * MAX_NAME)
    values, kinds = [], []
    for t in raw:
        try:
            tg = parse(t, collections)
        except TargetError as exc:
            fail("target", str(exc))
        v = value(str(tg))
        if v is None:
            fail("target", f"'{t}' is not a quantity of this structure ({tg.kind.pattern}: {tg.kind.what}); targets are "
                           f"{known(collections)}")
        values.append(float(v))
        kinds.append(tg.kind)
    units = sorted({k.unit for k in kinds})
    if len(units) > 1:
        fail("target", f"targets {raw} have different units ({', '.join(units)}); one parameter value must fit them all")
    unit = units[0]
    b = entry["bounds"]
    if not (isinstance(b, list) and len(b) == 2):
        fail("bounds", f"must be [lower, upper], e.g. [\"1 {unit}\", \"10 {unit}\"]")
    try:
        lo, hi = (float(v) if kinds[0].number and isinstance(v, (int, float)) and not isinstance(v, bool)
                  else to_si(v, unit, f"{file}: {where}.bounds[{k}]") for k, v in enumerate(b))
    except UnitError as exc:
        raise TargetError(str(exc)) from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        fail("bounds", f"must be finite, got {b!r}")
    if not lo < hi:
        fail("bounds", f"lower bound {b[0]!r} is not below the upper {b[1]!r}; swap them")
    if lo < 0 or (lo == 0 and not any(k.log for k in kinds) and kinds[0].attribute not in ("mass", "inertia")):
        fail("bounds", f"lower bound {b[0]!r} {'is negative' if lo < 0 else 'is 0'}: a {kinds[0].what} must stay "
                       "above 0 while it is updated; give a positive lower bound")
    if not all(math.isclose(v, values[0], rel_tol=1e-12) for v in values):
        fail("target", f"the targets start from different values {values}; a shared parameter needs equal starting "
                       "values")
    if not lo <= values[0] <= hi:
        fail("bounds", f"the current value {values[0]:g} (SI) lies outside [{lo:g}, {hi:g}]; widen the bounds or "
                       "change the structure")
    return ParameterSpec(name, [str(t) for t in raw], (lo, hi), unit, all(k.log for k in kinds),
                         values[0])


def read_parameters(reader, data: dict, value: Callable, collections) -> list:
    """The ``[[parameters]]`` of a structure's file (``reader``: its :class:`pcbdyn.inputs.Reader`,
    ``data`` the parsed file) checked by :func:`parameter_spec` against ``value(target)``; a bad one is the
    reader's error (BoardError, BoxError, ...)."""
    out = []
    for i, p in enumerate(reader.list(data, "parameters")):
        try:
            out.append(parameter_spec(p, f"parameters[{i}]", value, reader.file, collections))
        except TargetError as exc:
            raise reader.error(str(exc)) from None
    reader.unique([p.name for p in out], "parameters", "name")
    return out


# ------------------------------------------------------------------------------------ TOML slots
def _entry(doc, target: Target):
    """The TOML table holding ``target``'s entry in the parsed document ``doc`` (tomlkit or dict)."""
    if target.name is None:
        if target.collection not in doc:
            raise TargetError(f"target {target}: the file has no [{target.collection}] table")
        return doc[target.collection]
    for i, e in enumerate(doc.get(target.collection, [])):
        if entry_name(target.collection, e, i) == target.name:
            return e
    raise TargetError(f"target {target}: no [[{target.collection}]] entry is called '{target.name}'")


def read(doc, target) -> object:
    """The raw value of ``target`` (a Target or its text) in the parsed document (None when absent)."""
    tg = target if isinstance(target, Target) else parse(target)
    node = _entry(doc, tg)
    for key in tg.kind.keys:
        if not hasattr(node, "get") or key not in node:
            return None
        node = node[key]
    return node


def formatted(target, value: float):
    """``value`` [SI] of ``target`` (a Target, its text, or a :class:`Kind`) as written in the file: a
    quantity string in the kind's display unit at full precision (the file rebuilds the same model), or
    a bare number for a factor."""
    kind = target if isinstance(target, Kind) else (target if isinstance(target, Target) else parse(target)).kind
    return float(value) if kind.number else quantity(value, kind.unit)


def quantity(value: float, unit: str) -> str:
    """``value`` [SI] as a quantity string in ``unit`` at full precision, e.g. "3.19 mm"."""
    return f"{from_si(float(value), unit)!r} {unit}"


def write(doc, target, value: float) -> None:
    """Set ``target`` to ``value`` [SI] in the tomlkit document ``doc`` in place (comments and layout of
    the rest are kept; keys the value replaces, ``Kind.excludes``, are removed)."""
    tg = target if isinstance(target, Target) else parse(target)
    node = _entry(doc, tg)
    *inner, last = tg.kind.keys
    for key in inner:
        if key not in node or not hasattr(node[key], "get"):
            raise TargetError(f"target {tg}: the entry has no table '{key}' to write {last} into; give it as a "
                              f"table (e.g. {key} = {{ ... }})")
        node = node[key]
    for key in tg.kind.excludes:
        if key in node:
            del node[key]
    unit = _unit_of(node.get(last)) if not tg.kind.number else None
    node[last] = quantity(value, unit) if unit else formatted(tg, value)


def _unit_of(raw) -> str | None:
    """The unit text the user wrote ``raw`` with (e.g. "GPa" of "26 GPa"), to write the new value the
    same way; None when there is none to follow."""
    m = re.match(r"^\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*(\S.*?)\s*$", raw) if isinstance(raw, str) else None
    if m is None:
        return None
    try:
        registry().Quantity(1.0, m.group(1))
    except Exception:  # pint raises several unrelated types for text it cannot read
        return None
    return m.group(1)


def append_entry(doc, collection: str, fields: dict, note: str) -> None:
    """Append a table of ``fields`` to the array of tables ``collection`` of the tomlkit document ``doc``
    (made when absent), headed by the comment ``note`` (where the entry came from); the rest of the
    document is kept as written."""
    table = tomlkit.table()
    table.add(tomlkit.comment(note))
    for key, value in fields.items():
        table.add(key, value)
    if collection not in doc:
        doc.add(collection, tomlkit.aot())
    doc[collection].append(table)


def assignments(parameters, values: dict) -> dict:
    """{target: value [SI]} of the ``parameters`` (ParameterSpec) named in ``values`` {name: SI}: each
    parameter's value goes to every target it shares."""
    return {t: float(values[p.name]) for p in parameters if p.name in values for t in p.targets}


def updated_text(text: str, assignments: dict) -> str:
    """The TOML ``text`` with each target of ``assignments`` {target: value [SI]} set (:func:`write`),
    everything else as the user wrote it."""
    doc = tomlkit.parse(text)
    for target, value in assignments.items():
        write(doc, target, value)
    return tomlkit.dumps(doc)
