"""Fields of UFF records: the numbers on a data line (any width, run together, 'D' exponents), records read
across line breaks, node labels. Shared by the readers of :mod:`.uff` and :mod:`.uff_geometry`."""

from __future__ import annotations

import math
import re

from .data import TestDataError

_NUM = re.compile(rb"[-+]?(?:(?:\d+\.\d*|\.\d+|\d+)(?:[ED][-+]?\d+)?|nan|inf(?:inity)?)", re.IGNORECASE)


def numbers(line: bytes, where: str, nan: bool = False) -> list:
    """The numbers on one data line; any other character on it, or a value that is not finite (``nan``:
    NaN allowed, an FRF value not measured), is an error naming ``where``."""
    rest = _NUM.sub(b" ", line).strip()
    if rest:
        text = line.decode("latin-1").strip()[:60]
        raise TestDataError(f"{where}: '{rest.decode('latin-1')[:20]}' is not a number (the line reads '{text}')")
    out = [float(t.replace(b"D", b"E").replace(b"d", b"e")) for t in _NUM.findall(line)]
    if not all(math.isfinite(v) or (nan and math.isnan(v)) for v in out):
        text = line.decode("latin-1").strip()[:60]
        raise TestDataError(f"{where}: a value is not a finite number (the line reads '{text}'); write a number there")
    return out


class Cursor:
    """Reads the numbers of a dataset's lines record by record, across line breaks.

    ``take(n, what, end=True)`` returns the next n numbers; with ``end`` the record must finish
    there (no numbers left on its last line). ``first`` is the 0-based line of ``lines[0]`` in the
    dataset, for the messages."""

    def __init__(self, lines, first: int):
        self.lines, self.first = lines, first
        self.i = 0
        self.buf = []

    def take(self, n: int, what: str, end: bool = True) -> list:
        while len(self.buf) < n:
            if self.i >= len(self.lines):
                raise TestDataError(f"the dataset ends before {what} ({len(self.buf)} of {n} values found)")
            self.buf.extend(numbers(self.lines[self.i], f"{what}, line {self.first + self.i + 1} of the dataset"))
            self.i += 1
        out, self.buf = self.buf[:n], self.buf[n:]
        if end and self.buf:
            raise TestDataError(f"{what}: expected {n} values, found {n + len(self.buf)} "
                                f"(line {self.first + self.i} of the dataset)")
        return out


def label(n, where: str) -> int:
    """A node label: a whole number from 1 to 2^31 - 1 (the standard's I10 field)."""
    if not (n == int(n) and 1 <= n < 2**31):
        raise TestDataError(f"{where}: node label {n:g} is not a whole number from 1 to 2147483647")
    return int(n)
