"""The input kinds of pcbdyn as the fuzzer sees them: seed files (the bundled examples and test data), how
one is mutated (structured or byte-level) and the reader at its validation boundary. Each :class:`Kind`
makes a mutated input file in a folder and reads it; :func:`outcome.classify` judges what came out."""

from __future__ import annotations

import math
import shutil
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Callable

import numpy as np

from fuzz_mutate import Source, dump_toml, mutate_bytes, mutate_csv, mutate_toml, mutate_uff

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
BOARDS = [EXAMPLES / n / "board.toml" for n in ("six_part_card", "plain_plate", "wedge_locked", "kicad_board")]
BOARDS += sorted((ROOT / "tests" / "data" / "boards").glob("*.toml"))
LIBRARY = sorted((ROOT / "library").glob("*.toml"))


@dataclass
class Kind:
    """``make(seed, src, folder) -> (path, known invalid)`` writes one mutated input; ``read(path)`` reads it
    at pcbdyn's boundary (the result is checked for NaN); ``seeds``: what ``make`` starts from."""

    name: str
    seeds: Callable
    make: Callable
    read: Callable

    def one(self, src: Source, folder: Path) -> tuple:
        """(path, known invalid) of one mutated input made from a seed chosen by ``src``."""
        return self.make(src.choice(self.seeds()), src, folder)


def _write(folder: Path, name: str, blob: bytes) -> Path:
    p = folder / name
    p.write_bytes(blob)
    return p


def toml_kind(name: str, seeds: Callable, read: Callable, file: str, known_invalid=()) -> tuple:
    """The structured (field) and byte-level kinds of a TOML input."""

    def structured(seed, src, folder):
        doc, invalid = mutate_toml(tomllib.loads(seed.read_text()), src, known_invalid)
        return _write(folder, file, dump_toml(doc)), invalid

    def raw(seed, src, folder):
        blob, invalid = mutate_bytes(seed.read_bytes(), src)
        return _write(folder, file, blob), invalid

    return Kind(f"{name}", seeds, structured, read), Kind(f"{name} bytes", seeds, raw, read)


def csv_kind(name: str, seeds: Callable, read: Callable, file: str, numeric, key: bool) -> tuple:
    def structured(seed, src, folder):
        text, invalid = mutate_csv(seed.read_text(), src, numeric, key)
        return _write(folder, file, text.encode("utf-8", "surrogatepass")), invalid

    def raw(seed, src, folder):
        blob, invalid = mutate_bytes(seed.read_bytes(), src)
        return _write(folder, file, blob), invalid

    return Kind(name, seeds, structured, read), Kind(f"{name} bytes", seeds, raw, read)


# ------------------------------------------------------------------------------- known invalid fields


def _modes(doc, src):
    doc["analysis"] = {"modes": src.choice([201, 1000, 10**9, 0, -3, 2.5, "12"])}
    return True


def _repeated_vertex(doc, src):
    poly = doc.get("board", {}).get("outline", {}).get("polygon")
    if not isinstance(poly, list) or len(poly) < 3:
        return False
    k = src.integer(0, len(poly) - 1)
    poly.insert(k, list(poly[k]))
    return True


def _empty_target(doc, src):
    params = doc.get("parameters")
    if not isinstance(params, list) or not params or not isinstance(params[0], dict):
        return False
    src.choice(params)["target"] = []
    return True


def _library_value(doc, src):
    pkg = doc.get("package")
    if not isinstance(pkg, dict):
        return False
    key = src.choice(["mass", "equivalent_thickness", "size"])
    bad = src.choice(["0 g", "-8 g"]) if key == "mass" else src.choice(["0 mm", "-3 mm"])
    pkg[key] = [bad, "30 mm"] if key == "size" else bad
    return True


# ------------------------------------------------------------------------------- seeds made once


@cache
def uff_seeds() -> tuple:
    """Two UFF files written by pcbdyn (units, points and six modes on the six-part card's grid; one with
    FRFs too) and a test geometry with coordinate systems, trace lines and elements
    (tests/data/uff/node_systems.uff), in a folder of their own."""
    import tempfile

    from pcbdyn.testdata import FRFs, MeasuredModes, TestData, read_points_csv, write_uff
    from pcbdyn.testdata.data import Dofs

    folder = Path(tempfile.mkdtemp(prefix="pcbdyn-fuzz-seeds-"))
    pts, dofs = read_points_csv(EXAMPLES / "six_part_card" / "points.csv")
    rng = np.random.default_rng(1)
    x, y = pts.xyz[:, 0] / pts.xyz[:, 0].max(), pts.xyz[:, 1] / pts.xyz[:, 1].max()
    shapes = np.column_stack([np.sin(np.pi * (i + 1) * x) * np.sin(np.pi * (j + 1) * y)
                              for i, j in ((0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (0, 2))])
    shapes = shapes[pts.index(dofs.point_ids)] + 1e-3 * rng.standard_normal((len(dofs), 6))
    modes = MeasuredModes(pts, dofs, [160.0, 230.0, 300.0, 420.0, 510.0, 600.0], shapes, np.full(6, 0.01))
    write_uff(folder / "modes.uff", TestData(pts, modes))
    f = np.arange(0.0, 50.0, 2.0)
    H = (1.0 / (1e6 - (2 * np.pi * f) ** 2 * 1.0 + 0j))[:, None, None] * np.ones((1, 2, 1))
    resp = Dofs(pts.ids[:2], np.tile([0.0, 0.0, 1.0], (2, 1)))
    frfs = FRFs(pts, f, H, "receptance", resp, Dofs(pts.ids[:1], [0.0, 0.0, 1.0]))
    write_uff(folder / "frfs.uff", TestData(pts, modes.subset([0, 1]), frfs), binary=False)
    shutil.copy(Path(__file__).resolve().parents[1] / "data" / "uff" / "node_systems.uff", folder / "geometry.uff")
    return folder / "modes.uff", folder / "frfs.uff", folder / "geometry.uff"


@cache
def study_seeds() -> tuple:
    """The bundled study.toml files with their board and points as absolute paths (the mutant lives
    elsewhere)."""
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="pcbdyn-fuzz-seeds-"))
    out = []
    for p in sorted((EXAMPLES / "studies").glob("*.toml")):
        text = p.read_text()
        for rel in ("../six_part_card/board.toml", "../six_part_card/points.csv"):
            text = text.replace(f'"{rel}"', f'"{(p.parent / rel).resolve()}"')
        (folder / p.name).write_text(text)
        out.append(folder / p.name)
    return tuple(out)


@cache
def joint_seed() -> tuple:
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="pcbdyn-fuzz-seeds-"))
    card = EXAMPLES / "six_part_card"
    (folder / "calibration.toml").write_text(
        f'[[boards]]\nboard = "{card / "board.toml"}"\nfrequencies = "{card / "measured_frequencies_table_7_2.csv"}"\n'
        f'[[boards]]\nboard = "{card / "board.toml"}"\ntest = "{uff_seeds()[0]}"\n')
    return (folder / "calibration.toml",)


@cache
def history_seed() -> tuple:
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="pcbdyn-fuzz-seeds-"))
    (folder / "history.csv").write_text("# a sampled shock\ntime [ms],acceleration [g]\n0,0\n0.05,463\n0.1,882\n"
                                        "0.15,1214\n0.2,1427\n0.25,1500\n0.3,1427\n0.35,1214\n0.4,882\n0.5,0\n")
    return (folder / "history.csv",)


@cache
def psd_seed() -> tuple:
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="pcbdyn-fuzz-seeds-"))
    (folder / "psd.csv").write_text("# a random-vibration profile\nfrequency [Hz],psd [g^2/Hz]\n20,0.01\n80,0.04\n"
                                    "350,0.04\n2000,0.007\n")
    return (folder / "psd.csv",)


@cache
def six_part_card():
    from pcbdyn.board import load_board

    return load_board(EXAMPLES / "six_part_card" / "board.toml")


# ------------------------------------------------------------------------------- readers


def _read_library(p):
    from pcbdyn.components.writer import read_entry

    _, package, records = read_entry(p)
    return package, [(r.value, r.std, r.before) for r in records]


def _read_uff(p):
    from pcbdyn.testdata import read_uff

    data = read_uff(p)
    return data.points, data.modes, None if data.frfs is None else data.frfs.frequencies


def _read_kicad(folder):
    def read(p):
        from pcbdyn.board import BoardError, load_board
        from pcbdyn.ecad import import_kicad

        result = import_kicad(p, EXAMPLES / "kicad_board" / "map.toml")
        out = folder / "imported.toml"
        out.write_text(result.text)
        try:
            return load_board(out)
        except BoardError as exc:
            raise BoardError(f"{p.name}: {exc}") from None
    return read


def _quantity(seed, src, folder):
    """A quantity field of its own: a well-formed quantity must read as its number, a malformed one not."""
    (folder / "q.toml").write_text("")
    if src.integer(0, 1):
        return ("bad", src.bad_quantity(src.choice(["mm", "g", "N/m", "Hz"]))), True
    return ("any", src.choice([src.quantity(), src.text(12), f"{src.number()} mm"])), False


def _read_quantity(item):
    from pcbdyn.units import to_si

    how, text = item
    v = to_si(text, "mm", "q.toml: board.thickness")
    number = text.split()[0] if " " in text else None
    if how == "any" and text.endswith(" mm") and number is not None and math.isfinite(float(number)) \
            and abs(float(number)) < 1e300 and not math.isclose(v, float(number) * 1e-3, rel_tol=1e-12, abs_tol=1e-300):
        return float("nan")  # read as another number: reported as NaN
    return v


def kinds(folder: Path) -> list:
    """Every input kind, its mutants written into ``folder``."""
    from pcbdyn.board import load_board
    from pcbdyn.box import load_box
    from pcbdyn.ecad.packages import read_map
    from pcbdyn.problems.joint import read_joint
    from pcbdyn.problems.study_spec import read_spec
    from pcbdyn.targets import parse
    from pcbdyn.testdata import read_points_csv
    from pcbdyn.testdata.measured import read_frequency_table
    from pcbdyn.vibration.pulses import read_history, read_srs
    from pcbdyn.vibration.spectra import read_psd_csv

    points = tuple(EXAMPLES.glob("*/points.csv"))
    tables = tuple(EXAMPLES.glob("*/measured_frequencies_*.csv"))
    out = [
        *toml_kind("board.toml", lambda: BOARDS, load_board, "board.toml", (_modes, _repeated_vertex, _empty_target)),
        *toml_kind("box.toml", lambda: (EXAMPLES / "ribbed_box" / "box.toml",), load_box, "box.toml", (_modes,)),
        *toml_kind("library", lambda: LIBRARY, _read_library, "QFP.toml", (_library_value,)),
        *toml_kind("study.toml", study_seeds, lambda p: read_spec(p), "study.toml"),
        *toml_kind("calibration.toml", joint_seed, lambda p: [t.tests for t in read_joint(p)], "calibration.toml"),
        *toml_kind("map.toml", lambda: (EXAMPLES / "kicad_board" / "map.toml",), read_map, "map.toml"),
        *csv_kind("points.csv", lambda: points, lambda p: read_points_csv(p), "points.csv", ("point", "x", "y", "z"),
                  True),
        *csv_kind("frequencies.csv", lambda: tables, lambda p: read_frequency_table(p, six_part_card()),
                  "frequencies.csv", ("mode", "frequency_hz"), True),
        *csv_kind("psd.csv", psd_seed, read_psd_csv, "psd.csv", ("frequency", "psd"), False),
        *csv_kind("history.csv", history_seed, read_history, "history.csv", ("time", "acceleration"), False),
        *csv_kind("srs.csv", lambda: (EXAMPLES / "jedec_drop" / "jesd22_b111_srs.csv",), lambda p: read_srs(p, 10.0),
                  "srs.csv", ("frequency", "acceleration"), False),
        Kind("test.uff", uff_seeds, lambda s, src, f: _uff(s, src, f), _read_uff),
        Kind("test.uff bytes", uff_seeds, lambda s, src, f: _raw(s, src, f, "test.uff", utf8=False), _read_uff),
        Kind("kicad bytes", lambda: (EXAMPLES / "kicad_board" / "board.kicad_pcb",),
             lambda s, src, f: _raw(s, src, f, "board.kicad_pcb", utf8=False), _read_kicad(folder)),
        Kind("quantity", lambda: (None,), _quantity, _read_quantity),
        Kind("target", lambda: (None,), lambda s, src, f: (src.choice([src.text(20), "components.U1.thickness",
                                                                       "board.E", "a.b.c.d", "." * 50]), False),
             lambda t: parse(t)),
    ]
    return out


def _uff(seed, src, folder):
    text, invalid = mutate_uff(seed.read_text(encoding="latin-1"), src)
    return _write(folder, "test.uff", text.encode("latin-1", "replace")), invalid


def _raw(seed, src, folder, name, utf8):
    blob, invalid = mutate_bytes(seed.read_bytes(), src, utf8)
    return _write(folder, name, blob), invalid


#: the name each kind's messages must carry
MESSAGE_NAME = {"quantity": "q.toml", "target": "target"}
