"""A fitted calibration (:mod:`.calibration`) into the component library: one record per family with
where it came from (boards and test files by name and SHA-256, date, method, noise), pooled with the
runs the library already holds (:func:`pcbdyn.components.writer.add_calibration`)."""

from __future__ import annotations

import hashlib
import math
import uuid
from datetime import datetime, timezone
from pathlib import Path

from ..components.records import Record
from ..components.writer import add_calibration, read_entry
from .calibration import FAMILY_RANGE


def sha256(path) -> str:
    """The SHA-256 of a file's bytes (hex)."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def max_error(states) -> float:
    """The largest |frequency error| [%] over correlation states (nan when no mode paired)."""
    return max((s["max_freq_error_pct"] for s in states if s["max_freq_error_pct"] is not None), default=math.nan)


def run_records(cal) -> dict:
    """{family: Record} of a fitted calibration. A family whose value sits on a bound, or that the data
    do not determine, is flagged (kept on file, not pooled)."""
    run, date = uuid.uuid4().hex, datetime.now(timezone.utc).replace(microsecond=0)
    boards = tuple({"file": it.structure.path.name, "sha256": sha256(it.structure.path)} for it in cal.items)
    tests = tuple({"file": path.name, "sha256": sha256(path), "board": it.structure.path.name,
                   "configuration": c or "base"} for it in cal.items for c, path in it.files)
    out = {}
    for fam in cal.families:
        parts = [f"{it.structure.path.name}:{c.ref}" for it in cal.items for c in it.structure.components
                 if c.package == fam]
        reason = (f"at a bound of the fit: the data ask for a value outside [1/{FAMILY_RANGE:g}, {FAMILY_RANGE:g}] x "
                  "the library's" if fam in cal.at_bound else
                  "not determined by the data (rank-deficient equations)" if fam in cal.undetermined else "")
        extra = {"solver": cal.solver, "noise": cal.noise, "parts": parts, "iterations": int(cal.result.iterations),
                 "converged": bool(cal.result.converged)}
        out[fam] = Record(run, date, cal.method, cal.value(fam), cal.sd(fam), cal.start[fam][0], boards, tests,
                          max_error(cal.before), max_error(cal.after), bool(reason), reason, extra,
                          min(cal.sd_mesh(fam), cal.sd(fam)))
    return out


def check_library(cal, directory) -> None:
    """Every library file the calibration ``cal`` will write into ``directory`` (or start it from) reads
    as a valid entry: checked before the fit, so that a malformed file stops the run with nothing
    written (a LibraryError names the file, the field and the fix)."""
    for fam, (_, seed) in cal.start.items():
        path = Path(directory) / f"{fam}.toml"
        read_entry(path if path.is_file() else seed)


def write_library(cal, directory) -> dict:
    """Write every family's record of ``cal`` into the library folder ``directory`` (started from the
    entry the search path found when the folder has none yet). Returns, per family, the JSON
    ``families`` entry: the library's pooled ``equivalent_thickness_m`` and ``std_m`` after this run,
    ``before_m`` (the value the run started from), ``n_calibrations`` (runs on file), ``flagged`` (this
    run), this run's own ``run_m`` and ``run_std_m``, the ``reason`` of a flag and the ``file``."""
    check_library(cal, directory)
    out = {}
    for fam, rec in run_records(cal).items():
        written, pooled, n = add_calibration(directory, fam, rec, seed=cal.start[fam][1])
        out[fam] = {
            "equivalent_thickness_m": pooled.value if pooled else rec.before,
            "std_m": pooled.std if pooled else None,
            "before_m": rec.before,
            "n_calibrations": n,
            "flagged": written.flagged,
            "reason": written.reason,
            "run_m": rec.value,
            "run_std_m": rec.std if math.isfinite(rec.std) else None,
            "run_std_mesh_m": rec.std_mesh,
            "file": str(Path(directory) / f"{fam}.toml"),
        }
    return out
