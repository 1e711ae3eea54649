"""Text and JSON results, written atomically (see :mod:`pcbdyn.atomic`); ``-`` as a JSON path is the
standard output (a command run with ``--json -`` prints its human report on stderr instead)."""

from __future__ import annotations

import contextlib
import contextvars
import json
import math
import sys
from pathlib import Path

from ..atomic import atomic_path

__all__ = ["PLOT", "atomic_path", "json_to_stdout", "pyplot", "save_figure", "write_text", "write_json"]

#: the standard output a ``--json -`` run keeps for its JSON while its report goes to stderr
_JSON_STDOUT = contextvars.ContextVar("pcbdyn_json_stdout", default=None)


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)


#: savefig options of the plots (MAC matrices, spectra, maps, charts): 110 dpi, trimmed to the drawing
PLOT = {"dpi": 110, "bbox_inches": "tight"}


def pyplot():
    """matplotlib.pyplot on the Agg backend: every figure of a report is drawn for a file, never a window
    (a command may run where there is no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path, colours: int | None = None, **options) -> Path:
    """A matplotlib figure saved to ``path`` atomically (format from its suffix; ``options`` for
    savefig, e.g. dpi) and closed; returns ``path``. ``colours``: a PNG of that many colours (256 keep
    a mode picture's shading; the file is about a third of the full-colour one, so that a page
    embedding many stays small)."""
    import io

    import matplotlib.pyplot as plt

    path = Path(path)
    with atomic_path(path) as tmp:
        if colours is None:
            fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", **options)
        else:
            from PIL import Image

            buf = io.BytesIO()
            fig.savefig(buf, format="png", **options)
            buf.seek(0)
            with Image.open(buf) as im:
                im.convert("RGB").quantize(colours).save(tmp, format="PNG", optimize=True)
    plt.close(fig)
    return path


def finite(data):
    """``data`` (dicts, lists, numbers) with every float that is not finite replaced by None."""
    if isinstance(data, float):
        return data if math.isfinite(data) else None
    if isinstance(data, dict):
        return {k: finite(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [finite(v) for v in data]
    return data


def write_json(path, data) -> None:
    """``data`` as JSON to the file ``path``, or to the standard output when ``path`` is ``-``. JSON has no
    NaN or infinity: a number that is not finite (an undefined quantity) is written as null."""
    text = json.dumps(finite(data), indent=2, allow_nan=False) + "\n"
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
