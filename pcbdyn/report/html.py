"""One self-contained HTML page a reviewer reads: sections of tables, pictures (PNG embedded as
data URIs, so the page needs neither its folder nor a network), key/value lists and text, then
the versions of the software that made it. The layout is the Jinja2 template
``templates/page.html`` shipped with the package.

Use from a command (after its tables and PNG files are written)::

    page = Page("pcbdyn vibe: six-part card", subtitle="GEVS qualification, z axis")
    page.items("Inputs", {"board": describe_file(board_toml), "PSD": "gevs-qual (14.1 grms)"})
    page.table("Parts, worst margin first", dataframe, status=["bad", "good", ...], note="...")
    page.pictures("Board map", [out / "board_map.png"], ["margin per part"])
    page.text("Octave rule", ["f_board / f_chassis = 2.5: forward rule holds"])
    page.write(out / "report.html")

``page.view3d("Modes in 3-D", mode_view(...))`` adds an animated 3-D view (:mod:`.view3d`); the
first one brings plotly.js into the page. A click on a picture shows it full size.

Each call adds one section, in order; ``table`` takes a pandas DataFrame (column names carry
their units, e.g. "z_rms [mm]") or a list of dicts; numbers are shown with 4 significant digits.
``status`` (optional, one per row) colours rows "bad" or "good". ``write`` adds the versions
section and writes the page atomically.
"""

from __future__ import annotations

import base64
import hashlib
import platform
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path

import numpy as np

from .files import write_text

#: the size a page keeps under by leaving out optional pictures [bytes]
PAGE_BYTES = 14_500_000
#: the libraries whose versions a page records
VERSIONED = ("pcbdyn", "numpy", "scipy", "pandas", "matplotlib", "pint", "pyuff", "jinja2", "plotly")


def _cell(v) -> str:
    if v is None or (isinstance(v, float) and np.isnan(v)):
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return "inf" if np.isinf(v) else f"{float(v):.4g}"
    return str(v)


def describe_file(path) -> str:
    """'name (sha256 1a2b3c4d5e6f, 12.3 kB)': which input file a page was made from."""
    p = Path(path)
    data = p.read_bytes()
    return f"{p} (sha256 {hashlib.sha256(data).hexdigest()[:12]}, {len(data) / 1e3:.1f} kB)"


def versions() -> dict:
    """{name: version} of Python, the platform and :data:`VERSIONED` (those installed)."""
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for name in VERSIONED:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


class Page:
    """A page under construction; see the module docstring for the calls."""

    def __init__(self, title: str, subtitle: str | None = None):
        self.title, self.subtitle = title, subtitle
        self.sections: list[dict] = []

    def items(self, title: str, pairs: dict, note: str | None = None) -> "Page":
        self.sections.append({"kind": "items", "title": title, "note": note,
                              "rows": [(str(k), _cell(v)) for k, v in pairs.items()]})
        return self

    def table(self, title: str, data, status=None, note: str | None = None) -> "Page":
        import pandas as pd

        df = data if isinstance(data, pd.DataFrame) else pd.DataFrame(list(data))
        rows = [[_cell(v) for v in rec] for rec in df.itertuples(index=False)]
        status = list(status) if status is not None else [None] * len(rows)
        if len(status) != len(rows):
            raise ValueError(f"table '{title}': {len(status)} row statuses for {len(rows)} rows")
        text_cols = {i for i, c in enumerate(df.columns) if not pd.api.types.is_numeric_dtype(df[c])}
        self.sections.append({"kind": "table", "title": title, "note": note, "columns": [str(c) for c in df.columns],
                              "rows": list(zip(rows, status)), "text_cols": text_cols})
        return self

    def pictures(self, title: str, paths, captions=None, note: str | None = None, optional: bool = False) -> "Page":
        """PNG files with captions. ``optional``: pictures that another section shows too (the mode
        shapes of a 3-D view); the last of them are left out, and named, when the page would pass
        :data:`PAGE_BYTES`."""
        paths = [Path(p) for p in paths]
        captions = list(captions) if captions is not None else [p.stem for p in paths]
        pics = []
        for p, cap in zip(paths, captions):
            if not p.is_file():
                raise FileNotFoundError(f"picture {p} for the page section '{title}' does not exist")
            pics.append({"data": base64.b64encode(p.read_bytes()).decode("ascii"), "caption": cap,
                         "file": f"{p.parent.name}/{p.name}"})
        self.sections.append({"kind": "pictures", "title": title, "note": note, "pictures": pics,
                              "optional": optional})
        return self

    def _fit(self, html_bytes: int) -> bool:
        """Leave out the last optional pictures, as many as the page passes :data:`PAGE_BYTES` by;
        False when nothing was left out."""
        excess, dropped = html_bytes - PAGE_BYTES, False
        for s in reversed(self.sections):
            while excess > 0 and s["kind"] == "pictures" and s.get("optional") and s["pictures"]:
                pic = s["pictures"].pop()
                excess -= len(pic["data"]) + len(pic["caption"])
                s.setdefault("left_out", []).insert(0, pic["file"])
                s["note"] = (f"{len(s['left_out'])} picture(s) left out to keep the page under "
                             f"{PAGE_BYTES / 1e6:g} MB (the 3-D view shows every mode): {', '.join(s['left_out'])}")
                dropped = True
        return dropped

    def view3d(self, title: str, view: dict, note: str | None = None) -> "Page":
        """An animated 3-D view of modes: ``view`` from :func:`pcbdyn.report.view3d.mode_view`."""
        self.sections.append({"kind": "view3d", "title": title, "note": note, "view": view})
        return self

    def text(self, title: str, paragraphs, note: str | None = None) -> "Page":
        paras = [paragraphs] if isinstance(paragraphs, str) else list(paragraphs)
        self.sections.append({"kind": "text", "title": title, "note": note, "paragraphs": paras})
        return self

    def render(self) -> str:
        """The page as HTML text (the versions section included)."""
        from jinja2 import Environment, PackageLoader, select_autoescape

        env = Environment(loader=PackageLoader("pcbdyn.report", "templates"), autoescape=select_autoescape(["html"]))
        made = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        sections = self.sections + [{"kind": "items", "title": "Versions", "note": f"made {made}",
                                     "rows": list(versions().items())}]
        scripts = None
        if any(s["kind"] == "view3d" for s in sections):
            from .view3d import scripts as view_scripts

            scripts = view_scripts()
        return env.get_template("page.html").render(title=self.title, subtitle=self.subtitle, sections=sections,
                                                    version=versions()["pcbdyn"], scripts=scripts)

    def write(self, path) -> Path:
        """Write the page atomically, leaving out optional pictures while it would pass
        :data:`PAGE_BYTES`; returns its path."""
        html = self.render()
        while self._fit(len(html.encode("utf-8"))):
            html = self.render()
        write_text(path, html)
        return Path(path)
