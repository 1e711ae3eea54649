"""Writing a calibration run into a library folder: DIR/FAMILY.toml gains one ``[[calibrations]]``
record and the pooled ``equivalent_thickness`` and ``equivalent_thickness_std`` (:mod:`.records`).

Several calibrations may write one library at once (a design team, a batch of boards): the read,
the pooling and the write of a family file happen under a file lock (filelock, an OS lock released
when its process dies), so no record is lost; the file is replaced atomically after the new text
has been read back as a valid library file (:func:`pcbdyn.atomic.write_checked`), so a run killed
mid-write leaves the previous file as it was. The user's comments and layout are kept (tomlkit).
"""

from __future__ import annotations

from pathlib import Path

import tomlkit
from filelock import FileLock, Timeout

from ..atomic import write_checked
from ..inputs import read_toml
from .library import LibraryError, read_package
from .records import Pooled, Record, judge, length, pool, read_records, record_table

#: [s] how long a run waits for another run's write to the same family file
LOCK_TIMEOUT = 300.0


def lock_path(directory, family: str) -> Path:
    """The lock file that serialises writes of ``family`` in ``directory`` (hidden, beside the file)."""
    return Path(directory) / f".{family}.toml.lock"


def read_entry(path) -> tuple:
    """(text, Package, records) of a library file, every part checked (a LibraryError names the file,
    the field and the fix)."""
    text, data = read_toml(path, LibraryError)
    return text, read_package(path), read_records(Path(path), data)


def add_calibration(directory, family: str, record: Record, seed=None) -> tuple:
    """Add ``record`` to ``directory``/``family``.toml and pool every run into the family value.

    When the folder has no such file yet, it starts as a copy of ``seed`` (the entry the library
    search path found, e.g. the shipped one) with a comment saying so. The record is judged against
    the pooled earlier runs (:func:`.records.judge`) inside the lock. Returns (the record as
    written, Pooled or None when every run is flagged, number of runs in the file)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / f"{family}.toml"
    try:
        with FileLock(lock_path(directory, family), timeout=LOCK_TIMEOUT):
            source = path if path.is_file() else (Path(seed) if seed is not None else None)
            if source is None:
                raise LibraryError(f"{path}: no such library file and no entry to start it from; the family "
                                   f"'{family}' is not in the library")
            text, _, records = read_entry(source)
            if source != path:
                text = f"# {family}.toml started from {source} by pcbdyn calibrate\n{text}"
            doc = tomlkit.parse(text)
            rec = judge(record, records)
            records.append(rec)
            pooled = pool(records)
            _write_pooled(doc, pooled)
            if "calibrations" not in doc:
                doc["package"].add(tomlkit.nl())
                doc.append("calibrations", tomlkit.aot())
            doc["calibrations"].append(record_table(rec))
            write_checked(path, tomlkit.dumps(doc), read_entry, LibraryError)
    except Timeout:
        raise LibraryError(f"{path}: another calibration has held its lock ({lock_path(directory, family).name}) "
                           f"for {LOCK_TIMEOUT:.0f} s; wait for it and run again") from None
    return rec, pooled, len(records)


def _write_pooled(doc, pooled: Pooled | None) -> None:
    """Set the family value and its standard deviation (kept as they are when every run is flagged)."""
    if pooled is None:
        return
    pkg = doc["package"]
    pkg["equivalent_thickness"] = length(pooled.value)
    pkg["equivalent_thickness_std"] = length(pooled.std, 3)
