"""Mutations of pcbdyn's inputs, structured (a field of a TOML table, a cell of a CSV, a number or a line of a
UFF dataset) and byte-level; each returns the mutated input and whether it is known to be invalid (an
input that must be refused: a quantity with a decimal comma, a bare unit, arithmetic or a non-finite
number, a byte that is not UTF-8 in a text file, a measured frequency below zero, ...).

A mutation draws its choices from a :class:`Source`: hypothesis' data in the test suite (so a failure
shrinks to a small input) or a ``random.Random`` in the long benchmark run (benchmarks/fuzz_long.py)."""

from __future__ import annotations

import copy
import csv
import io
import re

#: units a quantity field may carry, and some it may not
UNITS = ["mm", "m", "in", "g", "kg", "GPa", "Pa", "kg/m^3", "N/m", "N*m/rad/m", "N*m^2", "kg*m^2", "deg", "Hz", "",
         "s", "mmm", "µm", "N m", "(N*m)/(rad*m)"]
JUNK = ["#", "$", "@", "!", ";", "?", "\\", "{", "'", "\u00a0", "\x00", "\u202e", "=", "[", ","]
QUANTITY = re.compile(r"^\s*[-+]?(?:\d|\.\d)[^=]*[A-Za-z]")


class Source:
    """Where a mutation draws its choices: hypothesis ``data`` or a ``random.Random`` (``rng``)."""

    def __init__(self, data=None, rng=None):
        self.data, self.rng = data, rng

    def integer(self, lo: int, hi: int) -> int:
        if self.rng is not None:
            return self.rng.randint(lo, hi)
        from hypothesis import strategies as st

        return self.data.draw(st.integers(lo, hi))

    def choice(self, seq):
        seq = list(seq)
        return seq[self.integer(0, len(seq) - 1)]

    def raw(self, n_max: int) -> bytes:
        if self.rng is not None:
            return bytes(self.rng.randrange(256) for _ in range(self.rng.randint(0, n_max)))
        from hypothesis import strategies as st

        return self.data.draw(st.binary(max_size=n_max))

    def text(self, n_max: int) -> str:
        if self.rng is not None:
            return "".join(chr(self.rng.choice([self.rng.randrange(32, 127), self.rng.randrange(0x80, 0x3000)]))
                           for _ in range(self.rng.randint(0, n_max)))
        from hypothesis import strategies as st

        return self.data.draw(st.text(max_size=n_max))

    def number(self) -> str:
        """A number as a file may hold it, ordinary or extreme."""
        return self.choice([
            str(self.integer(-1000, 1000)), f"{self.integer(0, 10**6) / 1000:g}", f"{self.integer(1, 99)}e{self.integer(-320, 320)}",
            "0", "-0", "1e-300", "1e300", "1e400", "-1", "0.0", "9" * self.integer(1, 400), ".5", "5."])

    def quantity(self) -> str:
        return f"{self.number()}{self.choice([' ', '', '  '])}{self.choice(UNITS)}"

    def bad_quantity(self, unit: str = "mm") -> str:
        """A quantity text that no quantity field may accept."""
        a, b = self.integer(0, 999), self.integer(0, 999)
        return self.choice([
            f"{a},{b} {unit}", f"{unit}", f" {unit} ", f"{a % 10}**{b % 10}**9 {unit}", f"{'9' * 400} {unit}",
            f"inf {unit}", f"-inf {unit}", f"nan {unit}", f"1e400 {unit}", f"{a} {unit}{self.choice(JUNK[:9])}",
            f"{a} {unit} {b}", f"{a}{self.choice(JUNK[:9])} {unit}", f"{a} {unit})", "x" * 100_000, "",
            f"{a}/{b + 1} {unit}", f"{a} ({unit}"])

    def value(self):
        """A TOML value of any type."""
        k = self.integer(0, 9)
        if k == 0:
            return self.choice([0, 1, -1, 2**62, -(2**63), self.integer(-10**6, 10**6)])
        if k == 1:
            return self.choice([0.0, -1.0, 1e308, -1e-308, float("nan"), float("inf"), float("-inf"), 0.5, 1e30])
        if k == 2:
            return self.choice([True, False])
        if k == 3:
            return self.text(20)
        if k in (4, 5):
            return self.quantity()
        if k == 6:
            return [self.quantity() for _ in range(self.integer(0, 4))]
        if k == 7:
            return {self.choice(["x", "name", "E", "at", ""]): self.quantity()}
        if k == 8:
            return self.choice(["x" * 70, "a.b", "U1\nU2", "../../etc/passwd", "clamped", "rigid", "x=0", "none",
                                "global", "\x00", "" ])
        return []


# ----------------------------------------------------------------------------------------- TOML


def _leaves(node, path=()):
    """Every (path, value) of a parsed TOML document, containers included."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _leaves(v, path + (i,))


def _set(doc, path, value):
    node = doc
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def _delete(doc, path):
    node = doc
    for p in path[:-1]:
        node = node[p]
    del node[path[-1]]


def mutate_toml(doc: dict, src: Source, known_invalid=(), gentle: bool = False) -> tuple:
    """(a mutated copy of the parsed document, known invalid): one to three random changes, or a random
    change or none and then one known to be invalid (a quantity no field may hold, or one of
    ``known_invalid``: functions ``make(doc, src) -> bool`` that make an invalid change where they can).
    ``gentle``: the random changes only scale quantities (inputs that mostly stay valid, to reach the mesh
    and the solve)."""
    seed = {p for p, v in _leaves(doc) if p and isinstance(v, str) and QUANTITY.match(v)}  # quantities of the seed
    doc = copy.deepcopy(doc)
    bad = src.integer(0, 3 if gentle else 2) == 0
    for _ in range(src.integer(0, 1) if bad else src.integer(1, 3)):
        _random_change(doc, src, gentle)
    if not bad:
        return doc, False
    quantities = [(p, v) for p, v in _leaves(doc) if p in seed and isinstance(v, str) and QUANTITY.match(v)]
    if known_invalid and (not quantities or src.integer(0, 2) == 0):
        return doc, bool(src.choice(known_invalid)(doc, src))
    if not quantities:
        return doc, False
    p, v = src.choice(quantities)
    _set(doc, p, src.bad_quantity(v.split()[-1] if " " in v.strip() else "mm"))
    return doc, True


def _random_change(doc, src: Source, gentle: bool = False) -> None:
    items = [(p, v) for p, v in _leaves(doc) if p]
    if not items:
        return
    path, value = src.choice(items)
    op = 9 if gentle else src.integer(0, 9)
    if op >= 8:  # a quantity scaled: mostly still valid, so the reader goes on past it
        quantities = [(p, v) for p, v in items if isinstance(v, str) and QUANTITY.match(v)]
        if quantities:
            p, v = src.choice(quantities)
            number, _, unit = v.strip().partition(" ")
            try:
                _set(doc, p, f"{float(number) * src.choice([0.5, 0.9, 1.1, 2.0, 10.0, 1e-3]):g} {unit}")
            except ValueError:
                pass
    elif op <= 2:
        _set(doc, path, src.value())
    elif op == 3 and isinstance(path[-1], str):
        _delete(doc, path)
    elif op == 4 and isinstance(value, dict):
        value[src.choice(["extra", "nmae", "mesh_sise", "x" * 80])] = src.value()
    elif op == 5 and isinstance(value, list) and value:
        value.insert(src.integer(0, len(value)), copy.deepcopy(src.choice(value)))
    elif op == 6 and isinstance(value, list):
        value.clear()
    else:
        strings = [(p, v) for p, v in items if isinstance(v, str)]
        if strings:
            p, v = src.choice(strings)
            k = src.integer(0, len(v))
            _set(doc, p, v[:k] + src.choice(JUNK + [src.text(3)]) + v[k:])


def dump_toml(doc: dict) -> bytes:
    """The document as TOML (tomlkit; values TOML cannot hold come out as a TOML syntax error)."""
    import tomlkit

    try:
        return tomlkit.dumps(doc).encode("utf-8", "surrogatepass")
    except Exception:  # noqa: BLE001 - e.g. a key tomlkit cannot write: write something TOML cannot read
        return repr(doc).encode("utf-8", "surrogatepass")


# ----------------------------------------------------------------------------------------- bytes


def mutate_bytes(blob: bytes, src: Source, utf8: bool = True) -> tuple:
    """(``blob`` with 1-4 byte-level changes, known invalid): a byte that is not UTF-8 in a file that must be
    UTF-8 text (``utf8``) is known invalid."""
    b = bytearray(blob)
    invalid = False
    for _ in range(src.integer(1, 4)):
        op = src.integer(0, 7)
        i = src.integer(0, len(b))
        j = min(len(b), i + src.integer(0, 64))
        if op == 0 and i < len(b):
            b[i] ^= 1 << src.integer(0, 7)
        elif op == 1:
            b[i:i] = src.raw(8)
        elif op == 2:
            del b[i:j]
        elif op == 3:
            b[i:i] = b[i:j] * src.integer(1, 3)
        elif op == 4:
            del b[i:]
        elif op == 5 and utf8:
            b[i:i] = src.choice([b"\xff", b"\xfe\xfe", b"\xc3", b"\xed\xa0\x80", b"\x80"])
            invalid = True
        elif op == 6 and i < len(b):
            b[i:i + 1] = src.choice([b"9", b"-", b".", b",", b"e", b"\n", b"\"", b"]", b"=", b"#", b" "])
        else:
            b[i:i] = src.choice([b"nan", b"inf", b"1e999", b"-1", b"0", b"\x00", b"\r", b"\t"])
    if invalid:
        try:
            bytes(b).decode("utf-8")
            invalid = False  # a later change cut the bad byte out again
        except UnicodeDecodeError:
            pass
    return bytes(b), invalid


# ----------------------------------------------------------------------------------------- CSV


def mutate_csv(text: str, src: Source, numeric=(), key: bool = False) -> tuple:
    """(mutated CSV text, known invalid): random changes, or a random change or none and then one known to
    be invalid: a cell of the ``numeric`` columns (header names) that is not a finite number, or, with
    ``key``, a data row given twice (a point and direction, or a mode, twice)."""
    lines = text.splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    rows = list(csv.reader([ln for ln in lines if not ln.startswith("#") and ln.strip()]))
    if len(rows) < 2:
        return text, False
    head, data = rows[0], rows[1:]
    bad = src.integer(0, 2) == 0
    for _ in range(src.integer(0, 1) if bad else src.integer(1, 3)):
        _csv_change(head, data, src)
    invalid = False
    if bad and data:
        r = src.integer(0, len(data) - 1)
        columns = [c for c, h in enumerate(head) if h.split("[")[0].strip().lower() in numeric and c < len(data[r])]
        if key and (not columns or src.integer(0, 1)):
            data.insert(r, list(data[r]))
            invalid = True
        elif columns:
            data[r][src.choice(columns)] = src.choice(["nan", "inf", "abc", "", "1,5", "1e999", "--1"])
            invalid = True
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows([head] + data)
    return "\n".join(comments) + ("\n" if comments else "") + out.getvalue(), invalid


def _csv_change(head, data, src: Source) -> None:
    op = src.integer(0, 5)
    r = src.integer(0, len(data) - 1) if data else 0
    c = src.integer(0, len(head) - 1) if head else 0
    if op <= 2 and data and c < len(data[r]):
        data[r][c] = src.choice([src.number(), src.text(6), "", "nan", "inf", "-inf", "1,5", "1e999",
                                 src.quantity(), "+z", "-x", "q", "0"])
    elif op == 3 and len(data) > 1:
        del data[r]
    elif op == 4 and head:
        head[c] = src.choice([src.text(8), head[c].replace("[", "("), head[c].split("[")[0], head[c] + " [kg]",
                              head[c].upper(), ""])
    elif head:
        for row in data:
            if c < len(row):
                del row[c]
        del head[c]


# ----------------------------------------------------------------------------------------- UFF


_TYPE = re.compile(r"^\s*(\d+)\s*$")


def _datasets(lines) -> list:
    """[(type, index of its type line)] of a UFF file's lines."""
    return [(int(_TYPE.match(lines[i + 1]).group(1)), i + 1) for i in range(len(lines) - 1)
            if lines[i].strip() == "-1" and _TYPE.match(lines[i + 1] or "")]


def mutate_uff(text: str, src: Source) -> tuple:
    """(mutated UFF text, known invalid): numbers and lines changed at random, or a random change or none and
    then one known to be invalid (a mode's frequency at or below 0, or below the 0.01 Hz floor of an elastic
    mode, or its damping ratio outside 0 to 1, a shape value NaN, a node of a mode given twice, a mode's shape
    zero at every node, a length factor of 0)."""
    lines = text.split("\n")
    bad = src.integer(0, 2) == 0
    for _ in range(src.integer(0, 1) if bad else src.integer(1, 3)):
        _uff_change(lines, src)
    if not bad:
        return "\n".join(lines), False
    sets = _datasets(lines)
    modes = [t for typ, t in sets if typ == 55 and t + 10 < len(lines)]
    units = [t for typ, t in sets if typ == 164 and t + 2 < len(lines)]
    op = src.integer(0, 3)
    invalid = False
    if op == 0 and modes:
        t = src.choice(modes)
        rec = lines[t + 8].split()
        if len(rec) >= 3:
            which = src.integer(0, 1)
            rec[2 * which] = src.choice(["-1.50000E+02", "0.00000E+00", "1.00000E-09", "9.99000E-03"] if which == 0
                                        else ["1.50000E+00", "-2.0E-02"])
            lines[t + 8] = " ".join(rec)
            invalid = True
    elif op == 1 and modes:
        t = src.choice(modes)
        node = t + 9 + 2 * src.integer(0, 1)
        if node + 1 < len(lines) and _TYPE.match(lines[node]) and lines[node + 1].split():
            if src.integer(0, 1):
                lines[node + 1] = lines[node + 1].replace(lines[node + 1].split()[0], "NaN", 1)
            else:
                lines[node + 2:node + 2] = lines[node:node + 2]
            invalid = True
    elif op == 3 and modes:
        invalid = _zero_shape(lines, src.choice(modes))
    elif units:
        t = units[0]
        lines[t + 2] = "  0.00000000000000000D+00" + lines[t + 2][25:]
        invalid = True
    return "\n".join(lines), invalid


def _zero_shape(lines, t: int) -> bool:
    """Every value of the dataset 55 whose type line is ``t`` set to zero (a record with no motion); whether
    the dataset held a node record to zero."""
    end = next((k for k in range(t + 9, len(lines)) if lines[k].strip() == "-1"), len(lines))
    changed = False
    for k in range(t + 9, end):
        if not _TYPE.match(lines[k]) and lines[k].split():
            lines[k] = " ".join("0.00000E+00" for _ in lines[k].split())
            changed = True
    return changed


def _uff_change(lines, src: Source) -> None:
    op = src.integer(0, 6)
    i = src.integer(0, len(lines) - 1)
    if op <= 3:
        tokens = lines[i].split()
        if tokens:
            k = src.integer(0, len(tokens) - 1)
            tokens[k] = src.choice([src.number(), "nan", "inf", "-1.0E+00", "0.00000E+00", "1E+999", "1.5",
                                    src.text(4), "9" * 40, "1.0D+00"])
            lines[i] = " ".join(tokens)
    elif op == 4:
        del lines[i]
    elif op == 5:
        lines.insert(i, lines[i])
    else:
        lines.insert(i, src.choice(["    -1", "", "  junk", "    55", "NONE"]))
