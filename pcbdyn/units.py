"""Quantities with units from input files ("2.8 mm", "26 GPa", "1e4 N*m/rad/m") to SI floats.

A quantity is read by one strict grammar before pint sees it: a decimal number (point, not comma;
optional exponent) and then a unit made of unit names, ``*``, ``/``, ``^`` or ``**`` with a number
exponent, and parentheses. Anything else (a decimal comma, a bare unit, a second number, arithmetic
such as ``9**9**9``, stray characters, a text longer than :data:`MAX_LENGTH`) is refused with a
message that names the field and the fix: pint alone evaluates expressions, reads "100,5 mm" as
1005 mm and a bare "mm" as 1 mm. pint then only names the unit; each field states the unit it
expects, so that a length given where a stiffness is wanted is caught. The value must be finite.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache

#: a standalone "g" or "G" in a unit: the acceleration of gravity where an acceleration is expected
_GRAVITY = re.compile(r"(?<![A-Za-z_])[gG](?![A-Za-z_0-9])")
#: longest quantity text read (a number with a compound unit is far shorter)
MAX_LENGTH = 100
_NUMBER = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")
_UNIT_TOKEN = re.compile(r"\s*(?:(?P<name>[^\W\d]\w*|%)|(?P<op>\*\*|[*/·^()])|(?P<exp>[-+]?\d+(?:\.\d+)?))")
_NOT_FINITE = re.compile(r"\s*[-+]?(?:nan|inf)", re.IGNORECASE)


#: length units of measured-data files (the points CSV's columns, a UFF file without dataset 164): metres per unit
LENGTHS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "in": 0.0254, "ft": 0.3048}


class UnitError(ValueError):
    """A quantity that is missing its unit, cannot be parsed, or has the wrong dimension."""


@lru_cache(maxsize=1)
def registry():
    import pint

    return pint.UnitRegistry()


@lru_cache(maxsize=64)
def _dimensionality(unit: str):
    return registry().Quantity(1.0, unit).dimensionality


def to_si(value, unit: str, where: str = "value") -> float:
    """``value`` (a string such as "2.8 mm") in SI base units, checked against ``unit``.

    ``unit`` is the expected unit written as pint understands it (e.g. "mm", "N*m/rad/m"); any
    unit of the same dimension is accepted. ``where`` names the field in the messages
    (e.g. "board.toml: board.thickness"). A bare number is accepted only for dimensionless fields.
    Vibration specifications write accelerations in g: where the expected dimension is not met,
    a standalone "g" or "G" is read as standard gravity (so "0.04 g^2/Hz" is an acceleration PSD,
    while "13 g" where a mass is expected stays grams).
    """
    dim = _dimensionality(unit)
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise UnitError(f"{where}: expected a quantity such as \"1 {unit}\", got {shown(value)}")
    if isinstance(value, (int, float)):
        if dim:
            raise UnitError(f"{where}: {shown(value)} has no unit; write it with one, e.g. \"{value} {unit}\"")
        return _finite(float(value), value, unit, where)
    number, text = _split(value, unit, where)
    factor, got = _unit(text, unit, where, value)
    if got != dim and _GRAVITY.search(text):
        gravity = _unit(_GRAVITY.sub("g_n", text), unit, where, value)
        factor, got = gravity if gravity[1] == dim else (factor, got)
    if got != dim:
        raise UnitError(
            f"{where}: {value!r} has unit '{text.strip() or 'no unit'}' ({got or 'dimensionless'}), expected a unit like '{unit}' "
            f"({dim or 'dimensionless'})"
        )
    return _finite(factor(number), value, unit, where)


#: the unit a quantity read in the key's unit is printed in, where that reads badly in a table (a modulus in
#: Pa: 2.6e+10)
PRINTED = {"Pa": "GPa"}


def printed_unit(unit: str) -> str:
    """The unit tables print a quantity read in ``unit`` in (``PRINTED``, else ``unit`` itself)."""
    return PRINTED.get(unit, unit)


def from_si(value: float, unit: str) -> float:
    """A SI value expressed in ``unit`` (e.g. 0.0035 -> 3.5 for "mm"); "1" leaves it as it is."""
    if unit in ("1", "dimensionless"):
        return float(value)
    ureg = registry()
    q = ureg.Quantity(float(value), ureg.Quantity(1.0, unit).to_base_units().units)
    return float(q.to(unit).magnitude)


def shown(value) -> str:
    """``value`` for a message (its repr), cut short when long."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:50]}... ({len(text)} characters)"


def _finite(v: float, value, unit: str, where: str) -> float:
    if not math.isfinite(v):
        raise UnitError(f"{where}: {shown(value)} is not a finite quantity; give a number such as \"1 {unit}\"")
    return v


def _split(value: str, unit: str, where: str) -> tuple:
    """(the number, the unit text) of a quantity string, by the grammar of the module docstring."""
    example = f"e.g. \"12.5 {unit}\"" if unit not in ("1", "dimensionless") else "e.g. \"0.5\""
    if len(value) > MAX_LENGTH:
        raise UnitError(f"{where}: {shown(value)} is too long for a quantity (at most {MAX_LENGTH} characters); "
                        f"write a number and a unit, {example}")
    m = _NUMBER.match(value)
    if m is None:
        if _NOT_FINITE.match(value):
            raise UnitError(f"{where}: {value!r} is not a finite quantity; give a number, {example}")
        raise UnitError(f"{where}: cannot read {value!r} as a quantity: it has no number; write the value with "
                        f"its unit, {example}")
    rest = value[m.end():]
    if re.match(r"\s*,\s*\d", rest):
        raise UnitError(f"{where}: {value!r} has a decimal comma; write a decimal point "
                        f"(\"{value.strip().replace(',', '.', 1)}\")")
    if rest and not rest[0].isspace() and not (rest[0].isalpha() or rest[0] in "%µμ°"):
        raise UnitError(f"{where}: cannot read {value!r} as a quantity ({rest.strip()[:20]!r} after the number); "
                        f"write one number and a unit, {example}")
    number = float(m.group(1))
    return number, rest


def _unit(text: str, unit: str, where: str, value: str) -> tuple:
    """(SI value of a number in unit ``text``, the dimensionality) or a UnitError naming the bad part."""
    pos, depth, prev = 0, 0, None
    while pos < len(text.rstrip()):
        t = _UNIT_TOKEN.match(text, pos)
        if t is None or (t.group("exp") and prev not in ("^", "**")) or (prev in ("^", "**") and not t.group("exp")):
            bad = text[pos:].strip()[:20]
            raise UnitError(f"{where}: cannot read {value!r} as a quantity ('{bad}' is not part of a unit); write one "
                            f"number and a unit, e.g. \"12.5 {unit}\"")
        prev = t.group("op") or "exp" if not t.group("name") else "name"
        depth += {"(": 1, ")": -1}.get(t.group("op"), 0)
        if depth < 0 or depth > 3:
            raise UnitError(f"{where}: cannot read {value!r} as a quantity (unbalanced parentheses in the unit)")
        pos = t.end()
    if depth:
        raise UnitError(f"{where}: cannot read {value!r} as a quantity (unbalanced parentheses in the unit)")
    return _conversion(text.strip().replace("·", "*"), where, value, unit)


def _conversion(text: str, where: str, value: str, unit: str) -> tuple:
    try:
        return _cached_conversion(text)
    except UnitError as exc:
        raise UnitError(f"{where}: cannot read {value!r} as a quantity ({exc}); write e.g. \"1 {unit}\"") from None


@lru_cache(maxsize=256)
def _cached_conversion(text: str) -> tuple:
    """(number -> SI value, dimensionality) of the unit ``text`` (checked by :func:`_unit`)."""
    ureg = registry()
    if not text:
        return float, ureg.Quantity(1.0).dimensionality
    try:
        one = ureg.Quantity(1.0, text)
        f1, f2 = (float(ureg.Quantity(x, text).to_base_units().magnitude) for x in (1.0, 2.0))
    except Exception as exc:  # pint raises several unrelated types for unknown units
        raise UnitError(f"'{text}' is not a unit pint knows: {type(exc).__name__}") from None
    if math.isclose(f2, 2.0 * f1, rel_tol=1e-12):
        return (lambda x: x * f1), one.dimensionality
    return (lambda x: float(ureg.Quantity(x, text).to_base_units().magnitude)), one.dimensionality  # offset units
