"""What a fuzzed input gives: ``ok`` (read, every number in the result finite), ``clean`` (one of pcbdyn's
input errors, one line, naming the file), or a failure: ``crash`` (any other exception: a traceback for
the user), ``hang`` (no answer within the time limit), ``nan`` (a result holding NaN or infinity),
``accepted`` (an input known to be invalid read without a word) or ``unnamed`` (a clean error that does
not name the file or that runs over lines)."""

from __future__ import annotations

import dataclasses
import signal
import traceback
from collections import Counter
from pathlib import Path

import numpy as np

FAILURES = ("crash", "hang", "nan", "accepted", "unnamed")
#: longest message an input error may have (a file name, a field, what is wrong and the fix)
MAX_MESSAGE = 2000


def input_errors() -> tuple:
    """The exception classes of pcbdyn's input boundaries."""
    from pcbdyn.components.library import LibraryError
    from pcbdyn.domain import StructureError
    from pcbdyn.ecad.kicad import KicadError
    from pcbdyn.fe import ModelError
    from pcbdyn.testdata import TestDataError
    from pcbdyn.units import UnitError
    from pcbdyn.updating.errors import UpdatingError
    from pcbdyn.vibration.spectra import VibrationError

    return StructureError, TestDataError, UnitError, LibraryError, ModelError, VibrationError, KicadError, UpdatingError


class _Hang(BaseException):
    pass


def _alarm(signum, frame):
    raise _Hang()


@dataclasses.dataclass
class Outcome:
    kind: str
    status: str
    detail: str = ""

    @property
    def failed(self) -> bool:
        return self.status in FAILURES


def classify(kind: str, read, name: str, invalid: bool = False, timeout: float = 10.0) -> Outcome:
    """Run ``read()`` (the reader of an input named ``name`` in messages) and say what it gave;
    ``invalid``: the input is known to be invalid, so reading it without an error is a failure."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        result = read()
    except _Hang:
        return Outcome(kind, "hang", f"no answer within {timeout:g} s")
    except input_errors() as exc:
        msg = str(exc)
        if (name is not None and name not in msg) or "\n" in msg or len(msg) > MAX_MESSAGE:
            return Outcome(kind, "unnamed", msg[:500])
        return Outcome(kind, "clean", msg[:300])
    except Exception:  # noqa: BLE001 - that is what this looks for
        return Outcome(kind, "crash", traceback.format_exc()[-3000:])
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    if invalid:
        return Outcome(kind, "accepted", "an invalid input was read without an error")
    bad = not_finite(result)
    if bad:
        return Outcome(kind, "nan", bad)
    return Outcome(kind, "ok")


def not_finite(obj, where: str = "result", depth: int = 0, seen=None) -> str:
    """Where ``obj`` (dataclasses, lists, dicts, arrays, numbers) holds a number that is not finite ("" when
    nowhere)."""
    seen = set() if seen is None else seen
    if depth > 8 or id(obj) in seen:
        return ""
    if isinstance(obj, (bool, int)) or obj is None or isinstance(obj, (str, bytes, Path)):
        return ""
    if isinstance(obj, (int, float, complex, np.number)):
        return "" if np.isfinite(obj) else f"{where} = {obj}"
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc" and not np.isfinite(obj).all():
            return f"{where} holds {obj[~np.isfinite(obj)][:3]}"
        return ""
    seen.add(id(obj))
    if dataclasses.is_dataclass(obj):
        items = [(f.name, getattr(obj, f.name)) for f in dataclasses.fields(obj)]
    elif isinstance(obj, dict):
        items = list(obj.items())
    elif isinstance(obj, (list, tuple)):
        items = list(enumerate(obj))
    else:
        return ""
    for k, v in items:
        bad = not_finite(v, f"{where}.{k}", depth + 1, seen)
        if bad:
            return bad
    return ""


class Tally:
    """Counts of outcomes per kind, and the first failures of each status."""

    def __init__(self):
        self.counts = Counter()
        self.examples = {}

    def add(self, outcome: Outcome, keep=None) -> None:
        self.counts[outcome.kind, outcome.status] += 1
        if outcome.failed:
            self.examples.setdefault((outcome.kind, outcome.status), (outcome.detail, keep))

    def kinds(self) -> list:
        return sorted({k for k, _ in self.counts})

    def table(self) -> str:
        """One line per kind: inputs, ok, clean errors and each failure status."""
        w = max([len(k) for k in self.kinds()] + [16]) + 2
        head = f"{'kind':<{w}}{'inputs':>8}{'ok':>7}{'clean':>7}" + "".join(f"{s:>10}" for s in FAILURES)
        rows = [head]
        total = Counter()
        for k in self.kinds():
            n = {s: self.counts[k, s] for s in ("ok", "clean", *FAILURES)}
            total.update(n)
            rows.append(f"{k:<{w}}{sum(n.values()):>8}{n['ok']:>7}{n['clean']:>7}"
                        + "".join(f"{n[s]:>10}" for s in FAILURES))
        rows.append(f"{'all':<{w}}{sum(total.values()):>8}{total['ok']:>7}{total['clean']:>7}"
                    + "".join(f"{total[s]:>10}" for s in FAILURES))
        return "\n".join(rows)
