"""Reading TOML input files (board.toml, box.toml, library files, study.toml) field by field, with the
file and the field named in every message and the fix said."""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from pathlib import Path

from .domain import MAX_MODES, StructureError
from .units import UnitError, from_si, shown, to_si

#: longest name of an entry (a part's ref, a fixture's or parameter's name) and of free text in a file
MAX_NAME = 64
MAX_TEXT = 1000
#: most entries an array of tables ([[components]], [[points]], ...) may hold
MAX_ENTRIES = 2_000
#: [SI] the range of a quantity read in a unit: its magnitude at most the upper limit, a positive one at
#: least the lower (values past these are typing errors, and make the FE model singular or overflow)
RANGES = {
    "mm": (1e-6, 100.0), "g": (1e-9, 1e4), "Pa": (1e3, 1e13), "kg/m^3": (1.0, 1e5), "N*m/rad/m": (1e-6, 1e15),
    "N/m": (1e-6, 1e15), "kg*m^2": (1e-15, 1e6), "N*m^2": (1e-9, 1e12), "deg": (0.0, 20 * math.pi),
    "Hz": (1e-3, 1e7),
}
#: largest input file read (bytes): a board.toml of MAX_ENTRIES parts is far smaller
MAX_FILE_BYTES = 20_000_000

#: the key that names an entry of a collection (default "name")
NAME_FIELD = {"components": "ref"}
#: prefix of the default name of an unnamed entry, by collection (the fixture's type for fixtures)
DEFAULT_PREFIX = {"masses": "m", "line_masses": "line_mass", "stiffeners": "stiffener", "regions": "region",
                  "plates": "plate", "ribs": "rib", "joints": "joint"}


def entry_name(collection: str, entry: dict, index: int) -> str:
    """The name of entry ``index`` (0-based) of ``collection``: its ``name`` (``ref`` for parts), else
    its kind's prefix and 1-based position (a fixture: its type, e.g. ``wedge_lock2``)."""
    key = NAME_FIELD.get(collection, "name")
    if key in entry:
        return str(entry[key])
    prefix = str(entry.get("type", collection)) if collection == "fixtures" else DEFAULT_PREFIX.get(collection, collection)
    return f"{prefix}{index + 1}"


def new_entry_name(text: str, used: set, fallback: str) -> str:
    """A name for a new entry made from ``text`` (a diagnosed effect's label): letters, digits, _ and -
    only (usable in targets), within the readers' length limit, and not in ``used`` (to which it is
    added)."""
    base = (re.sub(r"[^A-Za-z0-9_-]+", "_", text).strip("_") or fallback)[:MAX_NAME - 4]
    out, k = base, 2
    while out in used:
        out, k = f"{base}_{k}", k + 1
    used.add(out)
    return out


def check_name(name: str) -> str | None:
    """Why ``name`` cannot name an entry that targets address (None when it can)."""
    return f"'{name}' contains '.', which parameter targets use as a separator; rename it" if "." in name else None


def check_file(path, error=StructureError, limit: int = MAX_FILE_BYTES) -> Path:
    """``path`` as a Path once it is known to be a file of at most ``limit`` bytes; ``error`` otherwise."""
    path = Path(path)
    if not path.is_file():
        raise error(f"{path}: no such file")
    if path.stat().st_size > limit:
        raise error(f"{path.name}: {path.stat().st_size:,} bytes, more than an input file of this kind holds "
                    f"({limit:,}); is it the right file?")
    return path


def read_text(path, error=StructureError) -> str:
    """The text of an input file (TOML, CSV); ``error`` naming the file when it is missing, too large or not
    UTF-8 text."""
    path = check_file(path, error)
    try:
        return path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{path.name}: not UTF-8 text (byte {exc.start}); save it as UTF-8") from None


def read_csv(path, error, **options):
    """A pandas DataFrame of a CSV input file (UTF-8, ``#`` comments; ``options`` for pandas.read_csv);
    ``error`` naming the file for anything unreadable, in one line."""
    import io

    import pandas as pd

    text = read_text(path, error)
    try:
        return pd.read_csv(io.StringIO(text), comment="#", **options)
    except Exception as exc:  # noqa: BLE001 - pandas raises several types (parser, empty data, ...)
        raise error(f"{Path(path).name}: not a readable CSV file ({' '.join(str(exc).split())[:200]}); save it as "
                    "comma-separated text with one header line and the same number of fields on every line") from None


def read_toml(path, error=StructureError) -> tuple:
    """(text, parsed data) of a TOML file; ``error`` naming the file when it is missing, not UTF-8 text
    or not valid TOML."""
    path = Path(path)
    text = read_text(path, error)
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path.name}: not valid TOML: {exc}; fix the syntax at that line") from None


class Reader:
    """Field access for one input file: every failure raises ``error`` (a StructureError subclass)
    as ``<file>: <field>: <what is wrong and the fix>``."""

    def __init__(self, path, error=StructureError):
        self.file = Path(path).name
        self.error = error

    def fail(self, where: str, msg: str):
        raise self.error(f"{self.file}: {where}: {msg}")

    def table(self, data, where, allowed=None, required=()):
        """``data`` once it is a table whose keys are ``allowed`` (None: any) with the ``required`` ones."""
        if not isinstance(data, dict):
            self.fail(where, "must be a table ({ key = value, ... })")
        for k in data if allowed is not None else ():
            if k not in allowed:
                close = difflib.get_close_matches(k, allowed, n=1)
                hint = f"did you mean '{close[0]}'?" if close else f"allowed: {', '.join(allowed)}"
                self.fail(f"{where}.{k}", f"unknown field; {hint}")
        for k in required:
            if k not in data:
                self.fail(f"{where}.{k}", f"missing; add {k} = ...")
        return data

    def list(self, data, key, where=None, limit: int = MAX_ENTRIES):
        """The array ``key`` of ``data`` (empty when absent; ``where`` names it, default ``key``), of at
        most ``limit`` entries."""
        where = key if where is None else where
        v = data.get(key, [])
        if not isinstance(v, list):
            self.fail(where, f"must be an array, written [[{key}]] blocks or {key} = [...], got {shown(v)}")
        if len(v) > limit:
            self.fail(where, f"has {len(v):,} entries, more than the {limit:,} pcbdyn reads; is the file right?")
        return v

    def text(self, value, where, limit: int = MAX_TEXT, lines: bool = False) -> str:
        """A string field of at most ``limit`` printable characters (``lines``: line breaks and tabs too)."""
        if not isinstance(value, str):
            self.fail(where, f"must be text in quotes, got {shown(value)}")
        if len(value) > limit:
            self.fail(where, f"is {len(value):,} characters long; at most {limit} are allowed, shorten it")
        if not (value.replace("\n", "").replace("\t", "").replace("\r", "") if lines else value).isprintable():
            self.fail(where, f"{shown(value)} holds control characters (a line break, tab, ...); remove them")
        return value

    def name(self, collection: str, entry: dict, index: int, where: str) -> str:
        """The name of entry ``index`` of ``collection`` (:func:`entry_name`): text of at most
        :data:`MAX_NAME` printable characters without '.', which parameter targets use."""
        self.table(entry, where)
        key = NAME_FIELD.get(collection, "name")
        if key in entry:
            self.text(entry[key], f"{where}.{key}", MAX_NAME)
        name = entry_name(collection, entry, index)
        if (why := check_name(name)) is not None:
            self.fail(f"{where}.{key}", why)
        return name

    def unique(self, names, where, key):
        seen = set()
        for i, n in enumerate(names):
            if n in seen:
                self.fail(f"{where}[{i}].{key}", f"'{n}' is used twice; give each a different {key}")
            seen.add(n)

    def q(self, value, unit, where, positive=False, nonneg=False, limits=True):
        """``value`` in SI (:func:`pcbdyn.units.to_si`, expected ``unit``), within the :data:`RANGES` of
        that unit: its magnitude at most the upper limit and, when ``positive``, at least the lower
        (``limits=False``: any finite value, for those pcbdyn wrote itself, such as a run's std)."""
        try:
            v = to_si(value, unit, f"{self.file}: {where}")
        except UnitError as exc:
            raise self.error(str(exc)) from None
        if positive and not v > 0:
            self.fail(where, f"must be positive, got {shown(value)}")
        if nonneg and v < 0:
            self.fail(where, f"must not be negative, got {shown(value)}")
        lo, hi = RANGES.get(unit, (0.0, math.inf)) if limits else (0.0, math.inf)
        if abs(v) > hi or (positive and v < lo):
            self.fail(where, f"{shown(value)} is out of range; give {'a value' if positive else 'a magnitude'} "
                             f"{f'from {from_si(lo, unit):.3g} ' if positive else ''}up to {from_si(hi, unit):.3g} {unit}")
        return v

    def point(self, value, where, n: int = 2):
        if not (isinstance(value, list) and len(value) == n):
            example = ", ".join(f'"{c} mm"' for c in "xyz"[:n])
            self.fail(where, f"must be a point [{example}], got {shown(value)}")
        return tuple(self.q(v, "mm", f"{where}[{i}]") for i, v in enumerate(value))

    def analysis(self, data):
        """The ``[analysis]`` table of ``data`` as an :class:`pcbdyn.domain.Analysis` (defaults without it)."""
        from .domain import Analysis

        if "analysis" not in data:
            return Analysis()
        a = self.table(data["analysis"], "analysis", ["modes", "f_max"])
        modes = self.whole(a.get("modes", 12), "analysis.modes")
        if modes > MAX_MODES:
            self.fail("analysis.modes", f"{modes} modes are more than the {MAX_MODES} pcbdyn solves for; ask for fewer "
                                        "(a modal test rarely measures more than 30) or bound them with f_max")
        return Analysis(modes, self.q(a["f_max"], "Hz", "analysis.f_max", positive=True) if "f_max" in a else None)

    def number(self, value, where, lo=None, hi=None, note: str = ""):
        """A finite number (not a boolean) strictly between ``lo`` and ``hi`` (None: no limit on that side);
        ``note`` says in the message what the number means."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(where, f"must be a number, got {shown(value)}")
        if not math.isfinite(value):
            self.fail(where, f"must be a finite number, got {value}")
        if (lo is not None and value <= lo) or (hi is not None and value >= hi):
            bound = (f"must lie between {lo} and {hi} (exclusive)" if lo is not None and hi is not None
                     else f"must be > {lo:g}" if lo is not None else f"must be < {hi:g}")
            self.fail(where, f"{bound}{_note(note)}, got {value}")
        return float(value)

    def number_in(self, value, where, lo: float, hi: float, note: str = "") -> float:
        """A number (not a boolean) from ``lo`` to ``hi``, both included (a fraction, a share)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not lo <= value <= hi:
            self.fail(where, f"must be a number from {lo:g} to {hi:g}{_note(note)}, got {shown(value)}")
        return float(value)

    def whole(self, value, where, lo: int = 1, hi: int | None = None, note: str = "") -> int:
        """A TOML integer (not a boolean, not 3.0) from ``lo`` to ``hi`` (None: no upper limit), both included."""
        if isinstance(value, bool) or not isinstance(value, int) or value < lo or (hi is not None and value > hi):
            span = f"from {lo} to {hi}" if hi is not None else f"of at least {lo}"
            self.fail(where, f"must be a whole number {span}{_note(note)}, got {shown(value)}")
        return value

    def choice(self, value, where, options, what: str, explain: dict | None = None) -> str:
        """``value`` once it is one of the texts ``options``; the message names it as an unknown ``what``,
        the closest option and every option (with ``explain[option]``, what it means, where given)."""
        if not isinstance(value, str) or value not in options:
            close = difflib.get_close_matches(str(value)[:MAX_NAME], list(options), n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            listing = ", ".join(f"{o}{_note((explain or {}).get(o, ''))}" for o in options)
            self.fail(where, f"unknown {what} {shown(value)}{hint}; use one of {listing}")
        return value


def _note(text: str) -> str:
    """`` (text)`` to follow a value or bound in a message; empty without text."""
    return f" ({text})" if text else ""
