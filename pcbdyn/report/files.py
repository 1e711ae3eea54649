"""Text and JSON results, written atomically (see :mod:`pcbdyn.atomic`); ``-`` as a JSON path is the
standard output (a command run with ``--json -`` prints its human report on stderr instead)."""

from __future__ import annotations

import contextlib
import contextvars
import json
import sys

from ..atomic import atomic_path

__all__ = ["atomic_path", "json_to_stdout", "write_text", "write_json"]

#: the standard output a ``--json -`` run keeps for its JSON while its report goes to stderr
_JSON_STDOUT = contextvars.ContextVar("pcbdyn_json_stdout", default=None)


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def write_json(path, data) -> None:
    """``data`` as JSON to the file ``path``, or to the standard output when ``path`` is ``-``."""
    text = json.dumps(data, indent=2) + "\n"
    if str(path) == "-":
        stream = _JSON_STDOUT.get() or sys.stdout
        stream.write(text)
        stream.flush()
        return
    write_text(path, text)


@contextlib.contextmanager
def json_to_stdout():
    """While it lasts, what is printed goes to stderr and :func:`write_json` to ``-`` to the real
    standard output, so that ``pcbdyn ... --json - | jq`` reads JSON alone."""
    token = _JSON_STDOUT.set(sys.stdout)
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        _JSON_STDOUT.reset(token)
