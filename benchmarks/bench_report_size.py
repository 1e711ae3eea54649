"""The size of the build page (report.html: plotly.js, the animated 3-D view and the mode pictures) of
the example ribbed box meshed at 3.8 mm (about 50k DOF), with the example's 12 modes and with 40; the
page must stay under 15 MB. Prints the page, its 3-D view's data and its pictures, in MB, and the time
of the build. Run: python benchmarks/bench_report_size.py

Measured (49 626 DOF): 12 modes 8.56 MB (view data 1.33 MB, pictures 2.40 MB, plotly.js and the rest
4.84 MB); 40 modes 14.38 MB (view 3.49 MB, pictures 6.04 MB: the last ones, which would pass the page's
14.5 MB, are left out and named; the 3-D view shows every mode).
"""

from __future__ import annotations

import os
import re
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import tomlkit  # noqa: E402
from click.testing import CliRunner  # noqa: E402

from pcbdyn.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "ribbed_box" / "box.toml"
LIMIT_MB = 15.0


def measure(folder: Path, n_modes: int) -> None:
    doc = tomlkit.parse(EXAMPLE.read_text())
    doc["box"]["mesh_size"] = "3.8 mm"
    doc["analysis"]["modes"] = n_modes
    box = folder / f"box_{n_modes}.toml"
    box.write_text(tomlkit.dumps(doc))
    out, js = folder / f"out_{n_modes}", folder / f"b_{n_modes}.json"
    t0 = time.perf_counter()
    res = CliRunner().invoke(main, ["build", str(box), "--out", str(out), "--html", "--json", str(js)])
    took = time.perf_counter() - t0
    assert res.exit_code == 0, res.output
    page = (out / "report.html").read_text()
    view = sum(len(m) for m in re.findall(r'<script type="application/json" class="view-data">(.*?)</script>', page,
                                          re.S))
    pictures = sum(len(m) for m in re.findall(r'src="data:image/png;base64,([^"]*)"', page))
    dofs = int(re.search(r'"dofs": (\d+)', js.read_text()).group(1))
    size = len(page.encode()) / 1e6
    print(f"{dofs} DOF, {n_modes} modes: page {size:.2f} MB (3-D view data {view / 1e6:.2f} MB, pictures "
          f"{pictures / 1e6:.2f} MB, scripts and the rest {size - (view + pictures) / 1e6:.2f} MB), build "
          f"{took:.0f} s: {'under' if size < LIMIT_MB else 'OVER'} {LIMIT_MB:g} MB")


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        for n in (12, 40):
            measure(Path(tmp), n)
