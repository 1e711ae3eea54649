"""The calibration runs of a part family's library entry (``[[calibrations]]`` of FAMILY.toml) and how
the library pools them into the family's equivalent thickness and its standard deviation.

Each run (``pcbdyn calibrate``) leaves one record: its estimate ``value`` with standard deviation
``std`` and the part of it its mesh makes, ``std_mesh`` (systematic), the library value it started
from (``before``), where it came from (boards and test files with their SHA-256, date, method) and the
frequency errors before and after it. The family value is the inverse-variance weighted mean of the
runs that are not ``flagged`` (w_i proportional to 1/std_i^2: the Bayesian posterior mean of
independent Gaussian estimates under a flat prior). Its standard deviation has two parts: the
statistical one, sqrt(sum w_i^2 (std_i^2 - std_mesh_i^2)), widened by the Birge ratio
sqrt(chi^2 / (n - 1)) when the runs scatter more than they say (part-to-part and board-to-board
scatter that no single run sees), and the mesh one, sum w_i std_mesh_i, added whole: runs on meshes
alike err alike, so it does not average down. (Generalised least squares with fully correlated mesh
parts would be the textbook estimator, but with parts of different sizes it can put the mean outside
the runs, Peelle's puzzle, and it leans on the runs whose error is mostly mesh.) A new run more than :data:`FLAG_SIGMA` standard
deviations from the pooled others is flagged and left out, never averaged in silently; a user who
trusts it sets ``flagged = false``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from datetime import datetime

import numpy as np
import tomlkit

from ..inputs import MAX_TEXT, Reader
from ..units import from_si, shown
from .library import LibraryError

#: a run this many standard deviations from the pooled other runs is flagged (not averaged in)
FLAG_SIGMA = 3.0


@dataclass(frozen=True)
class Record:
    """One calibration run of one family: ``value``, ``std``, ``before`` and ``std_mesh`` (the systematic
    part of ``std``) [m]; ``boards`` and ``tests``
    (dicts with ``file``, ``sha256`` and, for a test, its ``board`` and ``configuration``);
    ``max_freq_error_before_pct``/``_after_pct`` over the run's test configurations; ``flagged`` and
    the ``reason``."""

    run: str
    date: datetime
    method: str
    value: float
    std: float
    before: float
    boards: tuple = ()
    tests: tuple = ()
    max_freq_error_before_pct: float = math.nan
    max_freq_error_after_pct: float = math.nan
    flagged: bool = False
    reason: str = ""
    extra: dict = field(default_factory=dict)
    std_mesh: float = 0.0


@dataclass(frozen=True)
class Pooled:
    """The family value of the runs not flagged: ``value``, ``std`` [m], ``n`` runs used, ``birge`` ratio
    (1 when the runs agree within their statistical standard deviations), ``mesh``, the systematic
    part the pooled value carries (the runs' ``std_mesh`` weighted as the value is), and ``stat``, the
    statistical part (std^2 = stat^2 + mesh^2)."""

    value: float
    std: float
    n: int
    birge: float
    mesh: float = 0.0
    stat: float = 0.0


#: keys of a record besides those of :data:`EXTRA_KEYS`, as written
KEYS = ("run", "date", "method", "value", "std", "std_mesh", "before", "flagged", "reason", "boards", "tests",
        "max_freq_error_before_pct", "max_freq_error_after_pct")
#: free-form provenance a record may carry (solver, noise, parts, library seed)
EXTRA_KEYS = ("solver", "noise", "parts", "iterations", "converged")


def read_records(path, data: dict) -> list:
    """The ``[[calibrations]]`` of a parsed library file ``data`` (read from ``path``) as Records; a
    LibraryError names the file, the record, the field and the fix."""
    r = Reader(path, LibraryError)
    return [_record(r, i, rec) for i, rec in enumerate(r.list(data, "calibrations", limit=math.inf))]


def _record(r: Reader, i: int, rec) -> Record:
    where = f"calibrations[{i}]"
    r.table(rec, where, KEYS + EXTRA_KEYS)
    for key in ("run", "date", "method", "value", "std", "before", "flagged"):
        if key not in rec:
            r.fail(f"{where}.{key}", "missing; every record written by pcbdyn calibrate has it (restore it, or delete "
                                     "the whole record)")
    if not isinstance(rec["date"], datetime):
        r.fail(f"{where}.date", f"must be a TOML date-time such as 2026-11-25T10:00:00Z, got {rec['date']!r}")
    if not isinstance(rec["flagged"], bool):
        r.fail(f"{where}.flagged", f"must be true or false, got {rec['flagged']!r}")
    value, std, before = (r.q(rec[k], "mm", f"{where}.{k}", limits=False) for k in ("value", "std", "before"))
    mesh = r.q(rec.get("std_mesh", "0 mm"), "mm", f"{where}.std_mesh", limits=False)
    if not (value > 0 and before > 0):
        r.fail(where, f"value and before must be positive lengths, got {rec['value']!r}, {rec['before']!r}")
    if not std > 0:
        r.fail(f"{where}.std", f"must be a positive length (a run always has a standard deviation), got {rec['std']!r}")
    if not 0 <= mesh <= std:
        r.fail(f"{where}.std_mesh", f"the mesh's part of std must lie between 0 and std ({rec['std']!r}), got "
                                    f"{rec.get('std_mesh')!r}")
    errors = [r.number(rec[k], f"{where}.{k}", note="percent") if k in rec else math.nan
              for k in ("max_freq_error_before_pct", "max_freq_error_after_pct")]
    run, method, reason = (r.text(rec.get(k, ""), f"{where}.{k}", MAX_TEXT) for k in ("run", "method", "reason"))
    files = {key: _files(r, rec.get(key, []), f"{where}.{key}") for key in ("boards", "tests")}
    return Record(run, rec["date"], method, value, std, before, files["boards"], files["tests"], errors[0], errors[1],
                  rec["flagged"], reason, {k: rec[k] for k in EXTRA_KEYS if k in rec}, mesh)


def _files(r, items, where) -> tuple:
    """The ``boards`` or ``tests`` of a record: inline tables of text (file, sha256, board, configuration)."""
    if not isinstance(items, list):
        r.fail(where, f"must be a list of {{ file = ..., sha256 = ... }} tables, got {shown(items)}")
    for k, item in enumerate(items):
        if not isinstance(item, dict) or not all(isinstance(v, str) for v in item.values()):
            r.fail(f"{where}[{k}]", f"must be a table of texts such as {{ file = \"board.toml\", sha256 = \"...\" }}, "
                                    f"got {shown(item)}")
        for key, v in item.items():
            r.text(v, f"{where}[{k}].{key}", MAX_TEXT)
    return tuple(items)


def pool(records) -> Pooled | None:
    """The pooled value of the records not flagged (module docstring); None when every record is
    flagged (or none)."""
    use = [r for r in records if not r.flagged]
    if not use:
        return None
    v = np.array([r.value for r in use])
    std = np.array([r.std for r in use])
    mesh = np.array([r.std_mesh for r in use])
    w = (1.0 / std**2) / np.sum(1.0 / std**2)
    mean = float(w @ v)
    n = len(use)
    birge = float(np.sqrt(np.sum((v - mean) ** 2 / std**2) / (n - 1))) if n > 1 else 1.0
    stat = float(np.sqrt(np.sum(w**2 * (std**2 - mesh**2)))) * max(1.0, birge)
    return Pooled(mean, math.hypot(stat, float(w @ mesh)), n, birge, float(w @ mesh), stat)


def judge(record: Record, others) -> Record:
    """``record`` flagged when it lies more than :data:`FLAG_SIGMA` standard deviations from the pooled
    ``others``, the mesh parts counted as fully correlated (a record flagged already, e.g. at a bound,
    stays as it is)."""
    ref = pool(others)
    if record.flagged or ref is None:
        return record
    stat2 = max(record.std**2 - record.std_mesh**2, 0.0)
    z = abs(record.value - ref.value) / math.sqrt(max(stat2 + ref.stat**2 + (record.std_mesh - ref.mesh) ** 2,
                                                      (1e-6 * record.std) ** 2))
    if z <= FLAG_SIGMA:
        return record
    return replace(record, flagged=True, reason=(
        f"{z:.1f} sigma from the pooled value of the other {ref.n} run(s), {from_si(ref.value, 'mm'):.4g} +- "
        f"{from_si(ref.std, 'mm'):.2g} mm: not averaged in (a different part, board or model? set flagged = "
        "false to count it)"))


def record_table(rec: Record):
    """``rec`` as a tomlkit table for ``[[calibrations]]`` (lengths as quantities in mm)."""
    t = tomlkit.table()
    t["run"] = rec.run
    t["date"] = rec.date
    t["method"] = rec.method
    t["value"] = length(rec.value)
    t["std"] = length(rec.std, 3)
    t["std_mesh"] = length(rec.std_mesh, 3)
    t["before"] = length(rec.before)
    t["flagged"] = rec.flagged
    if rec.reason:
        t["reason"] = rec.reason
    for key in ("max_freq_error_before_pct", "max_freq_error_after_pct"):
        v = getattr(rec, key)
        if math.isfinite(v):
            t[key] = round(float(v), 4)
    for key, value in rec.extra.items():
        t[key] = value
    for key in ("boards", "tests"):
        arr = tomlkit.array()
        for item in getattr(rec, key):
            it = tomlkit.inline_table()
            it.update(item)
            arr.append(it)
        arr.multiline(len(arr) > 1)
        t[key] = arr
    t.add(tomlkit.nl())
    return t


def length(value: float, digits: int = 6) -> str:
    """A length [m] as written in a library file, in mm to ``digits`` significant digits."""
    return f"{from_si(float(value), 'mm'):.{digits}g} mm"
