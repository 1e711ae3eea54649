"""The boards of a calibration and their tests: one board with its test files from the command line, or
several listed in a calibration file (``--joint calibration.toml``) and calibrated in one stacked
problem. A calibration file, paths relative to it::

    [[boards]]
    board = "card_a.toml"
    test = "card_a.uff"                       # modes (UFF dataset 55) of the base configuration
    configurations = { c2 = "card_a_c2.uff" } # optional: tests of the board's [[configurations]]

    [[boards]]
    board = "card_b.toml"
    frequencies = "card_b_frequencies.csv"    # or: measured frequencies (configuration, mode, frequency_hz)
"""

from __future__ import annotations

from pathlib import Path

from ..domain import StructureError
from ..inputs import MAX_NAME, Reader, read_toml
from ..testdata import TestDataError
from ..testdata.measured import read_frequency_table, read_tests
from .calibration import BoardTests, CalibrationError
from .load import load_structure


def load_board_tests(board, test=None, extras=(), frequencies=None) -> BoardTests:
    """A structure file and its tests: the UFF ``test`` of the base configuration and ``extras``
    [(configuration, UFF)], or a CSV of measured ``frequencies`` (one file for all configurations)."""
    structure = load_structure(board)
    if (test is None) == (frequencies is None):
        raise CalibrationError(f"{Path(board).name}: give its test (a UFF file) or its measured frequencies (a CSV "
                               "file), one of them")
    if frequencies is not None:
        tests = read_frequency_table(frequencies, structure)
        return BoardTests(structure, tests, [(c, Path(frequencies)) for c, _ in tests])
    tests = read_tests(structure, test, extras)
    return BoardTests(structure, tests, [(None, Path(test))] + [(c, Path(p)) for c, p in extras])


def read_joint(path) -> list:
    """The :class:`~.calibration.BoardTests` of every ``[[boards]]`` entry of a calibration file."""
    path = Path(path)
    _, data = read_toml(path, CalibrationError)
    r = Reader(path, CalibrationError)
    r.table(data, "top level", ["boards"], required=["boards"])
    entries = r.list(data, "boards")
    if not entries:
        r.fail("boards", "is empty; list each board with [[boards]] board = \"board.toml\", test = \"test.uff\"")
    out = []
    for i, e in enumerate(entries):
        where = f"boards[{i}]"
        r.table(e, where, ["board", "test", "frequencies", "configurations"], required=["board"])
        files = {k: _file(r, path, e[k], f"{where}.{k}") for k in ("board", "test", "frequencies") if k in e}
        extra = e.get("configurations", {})
        if not isinstance(extra, dict):
            r.fail(f"{where}.configurations", "must be a table of configuration = \"test file\", e.g. { c2 = \"c2.uff\" }")
        extras = [(r.text(c, f"{where}.configurations", MAX_NAME), _file(r, path, f, f"{where}.configurations.{c}"))
                  for c, f in extra.items()]
        try:
            out.append(load_board_tests(files["board"], files.get("test"), extras, files.get("frequencies")))
        except (StructureError, TestDataError) as exc:  # in a file the entry names: say which entry
            r.fail(where, str(exc))
    return out


def _file(r: Reader, base: Path, value, where: str) -> Path:
    if not isinstance(value, str) or not value:
        r.fail(where, f"must be a file name, got {value!r}")
    p = (base.parent / value) if not Path(value).is_absolute() else Path(value)
    if not p.is_file():
        r.fail(where, f"{value!r}: no such file (paths are relative to {base.name})")
    return p
