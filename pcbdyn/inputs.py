"""Reading TOML input files (board.toml, box.toml, library files, study.toml) field by field, with the
file and the field named in every message and the fix said."""

from __future__ import annotations

import difflib
import tomllib
from pathlib import Path

from .domain import StructureError
from .units import UnitError, to_si


def read_toml(path, error=StructureError) -> tuple:
    """(text, parsed data) of a TOML file; ``error`` naming the file when it is missing, not UTF-8 text
    or not valid TOML."""
    path = Path(path)
    if not path.is_file():
        raise error(f"{path}: no such file")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{path.name}: not UTF-8 text (byte {exc.start}); save it as UTF-8") from None
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

    def table(self, data, where, allowed, required=()):
        if not isinstance(data, dict):
            self.fail(where, "must be a table ({ key = value, ... })")
        for k in data:
            if k not in allowed:
                close = difflib.get_close_matches(k, allowed, n=1)
                hint = f"did you mean '{close[0]}'?" if close else f"allowed: {', '.join(allowed)}"
                self.fail(f"{where}.{k}", f"unknown field; {hint}")
        for k in required:
            if k not in data:
                self.fail(f"{where}.{k}", f"missing; add {k} = ...")
        return data

    def list(self, data, key):
        """The array of tables ``key`` of ``data`` (empty when absent)."""
        v = data.get(key, [])
        if not isinstance(v, list):
            self.fail(key, f"must be an array of tables: write [[{key}]] blocks")
        return v

    def unique(self, names, where, key):
        seen = set()
        for i, n in enumerate(names):
            if n in seen:
                self.fail(f"{where}[{i}].{key}", f"'{n}' is used twice; give each a different {key}")
            seen.add(n)

    def q(self, value, unit, where, positive=False, nonneg=False):
        try:
            v = to_si(value, unit, f"{self.file}: {where}")
        except UnitError as exc:
            raise self.error(str(exc)) from None
        if positive and not v > 0:
            self.fail(where, f"must be positive, got {value!r}")
        if nonneg and v < 0:
            self.fail(where, f"must not be negative, got {value!r}")
        return v

    def point(self, value, where, n: int = 2):
        if not (isinstance(value, list) and len(value) == n):
            example = ", ".join(f'"{c} mm"' for c in "xyz"[:n])
            self.fail(where, f"must be a point [{example}], got {value!r}")
        return tuple(self.q(v, "mm", f"{where}[{i}]") for i, v in enumerate(value))

    def analysis(self, data):
        """The ``[analysis]`` table of ``data`` as an :class:`pcbdyn.domain.Analysis` (defaults without it)."""
        from .domain import Analysis

        if "analysis" not in data:
            return Analysis()
        a = self.table(data["analysis"], "analysis", ["modes", "f_max"])
        modes = a.get("modes", 12)
        if isinstance(modes, bool) or not isinstance(modes, int) or modes < 1:
            self.fail("analysis.modes", f"must be a positive whole number, got {modes!r}")
        return Analysis(modes, self.q(a["f_max"], "Hz", "analysis.f_max", positive=True) if "f_max" in a else None)

    def number(self, value, where, lo=None, hi=None):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(where, f"must be a number, got {value!r}")
        if (lo is not None and value <= lo) or (hi is not None and value >= hi):
            self.fail(where, f"must lie between {lo} and {hi} (exclusive), got {value}")
        return float(value)
