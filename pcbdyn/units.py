"""Quantities with units from input files ("2.8 mm", "26 GPa", "1e4 N*m/rad/m") to SI floats.

pint does the parsing; each field states the unit it expects so that a length given where a
stiffness is wanted is caught with a message that names the file, the field and the fix.
"""

from __future__ import annotations

import re
from functools import lru_cache

#: a standalone "g" or "G" in a unit: the acceleration of gravity where an acceleration is expected
_GRAVITY = re.compile(r"(?<![A-Za-z_])[gG](?![A-Za-z_0-9])")


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
        raise UnitError(f"{where}: expected a quantity such as \"1 {unit}\", got {value!r}")
    if isinstance(value, (int, float)):
        if dim:
            raise UnitError(f"{where}: {value!r} has no unit; write it with one, e.g. \"{value} {unit}\"")
        return float(value)
    q = _parse(value, unit, where)
    if q.dimensionality != dim and _GRAVITY.search(value):
        gravity = _parse(_GRAVITY.sub("g_n", value), unit, where)
        q = gravity if gravity.dimensionality == dim else q
    if q.dimensionality != dim:
        got = f"{q.units:~}" or "no unit"
        raise UnitError(
            f"{where}: {value!r} has unit '{got}' ({q.dimensionality}), expected a unit like '{unit}' "
            f"({dim or 'dimensionless'})"
        )
    return float(q.to_base_units().magnitude)


def from_si(value: float, unit: str) -> float:
    """A SI value expressed in ``unit`` (e.g. 0.0035 -> 3.5 for "mm"); "1" leaves it as it is."""
    if unit in ("1", "dimensionless"):
        return float(value)
    ureg = registry()
    q = ureg.Quantity(float(value), ureg.Quantity(1.0, unit).to_base_units().units)
    return float(q.to(unit).magnitude)


def _parse(value: str, unit: str, where: str):
    ureg = registry()
    try:
        q = ureg.Quantity(value.strip())
    except Exception as exc:  # pint raises several unrelated types for bad text
        raise UnitError(f"{where}: cannot read {value!r} as a quantity ({exc}); write e.g. \"1 {unit}\"") from None
    return q if isinstance(q, ureg.Quantity) else ureg.Quantity(q)
