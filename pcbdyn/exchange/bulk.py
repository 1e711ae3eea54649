"""Nastran bulk data cards in large-field fixed format.

Every card is written with 16-character fields (name with ``*``, four fields a line, ``*``
continuation lines), so reals keep 10 significant digits: coordinates, section data and spring
constants survive the round trip to well below the 0.01 % that a frequency comparison needs.
``fields`` are the card's data fields in small-field numbering (field 2 onwards, eight per
logical line, the continuation fields left out), so a card reads as in the Quick Reference Guide.
"""

from __future__ import annotations

import numbers

WIDTH = 16


def field(value) -> str:
    """One 16-character field: blank for None, an integer, a real with a decimal point and
    exponent (10 significant digits where the exponent allows), or text."""
    if value is None:
        return " " * WIDTH
    if isinstance(value, (bool,)):
        raise TypeError("a bulk data field cannot be a bool")
    if isinstance(value, numbers.Integral):
        text = str(int(value))
    elif isinstance(value, numbers.Real):
        x = float(value)
        if x != x or x in (float("inf"), float("-inf")):
            raise ValueError(f"{x} cannot be written to a bulk data field")
        for digits in range(9, 0, -1):
            text = f"{x:.{digits}E}"
            if len(text) <= WIDTH:
                break
    else:
        text = str(value)
    if len(text) > WIDTH:
        raise ValueError(f"'{text}' does not fit a {WIDTH}-character field")
    return text.rjust(WIDTH)


def card(name: str, fields) -> str:
    """The lines of one card (ending with a newline); trailing blank fields are dropped."""
    values = list(fields)
    while values and values[-1] is None:
        values.pop()
    lines = []
    for start in range(0, max(len(values), 1), 4):
        head = f"{name}*" if start == 0 else "*"
        lines.append(f"{head:<8}" + "".join(field(v) for v in values[start:start + 4]).rstrip())
    return "\n".join(lines) + "\n"


def comment(text: str) -> str:
    """Comment lines ('$ ...') for each line of ``text``."""
    return "".join(f"$ {line}".rstrip() + "\n" for line in str(text).splitlines())
