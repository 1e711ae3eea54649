"""The library writer (pcbdyn.components.writer, records): pooling of calibration runs, flags, the
user's comments kept, 50 concurrent writers losing no record, a writer killed mid-write leaving the
previous file intact, malformed files refused with the file untouched."""

from __future__ import annotations

import math
import multiprocessing as mp
import os
import signal
import time
import uuid
from datetime import datetime, timezone

import pytest
from filelock import FileLock

from pcbdyn.components.library import LibraryError, read_package, shipped_library
from pcbdyn.components.records import Record, pool
from pcbdyn.components.writer import add_calibration, lock_path, read_entry

SEED = shipped_library() / "PGA.toml"


def record(value_mm, std_mm, run=None, mesh_mm=0.0) -> Record:
    return Record(run or uuid.uuid4().hex, datetime.now(timezone.utc).replace(microsecond=0), "freq", value_mm * 1e-3,
                  std_mm * 1e-3, 3.5e-3, ({"file": "b.toml", "sha256": "0" * 64},),
                  ({"file": "t.uff", "sha256": "1" * 64, "board": "b.toml", "configuration": "base"},), 8.0, 0.5,
                  std_mesh=mesh_mm * 1e-3)


def test_pooling_inverse_variance_birge_and_flag(tmp_path):
    """Runs pool by inverse variance (the Gaussian posterior mean); their scatter beyond their stds widens
    the std by the Birge ratio; a run beyond 3 sigma of the others is flagged and left out; the file
    keeps the seed's comments and text, and records the runs with units."""
    runs = [(4.0, 0.1), (4.3, 0.2), (3.9, 0.1)]
    for v, s in runs:
        add_calibration(tmp_path, "PGA", record(v, s), seed=SEED)
    w = [1 / s**2 for _, s in runs]
    mean = sum(wi * v for wi, (v, _) in zip(w, runs)) / sum(w)
    birge = math.sqrt(sum(wi * (v - mean) ** 2 for wi, (v, _) in zip(w, runs)) / 2)
    pkg = read_package(tmp_path / "PGA.toml")
    assert pkg.equivalent_thickness == pytest.approx(mean * 1e-3, rel=1e-5)
    assert pkg.equivalent_thickness_std == pytest.approx(math.sqrt(1 / sum(w)) * max(1, birge) * 1e-3, rel=1e-3)
    # a run far outside: flagged, the family value unchanged
    far, _, n = add_calibration(tmp_path, "PGA", record(6.0, 0.1), seed=SEED)
    assert far.flagged and "sigma from the pooled value of the other 3 run(s)" in far.reason and n == 4
    assert read_package(tmp_path / "PGA.toml").equivalent_thickness == pytest.approx(mean * 1e-3, rel=1e-5)
    text = (tmp_path / "PGA.toml").read_text()
    assert "# Pin-grid-array package" in text and "Steinberg package constant" in text  # the seed's comment and text
    assert 'std = "0.1 mm"' in text and "flagged = true" in text and text.count("[[calibrations]]") == 4


def test_library_list_and_show(tmp_path):
    """``pcbdyn library list`` finds the folder's entry first; ``library show`` tabulates the runs, plots
    them against the pooled value and its band, and writes them as JSON."""
    import json

    from click.testing import CliRunner

    from pcbdyn.cli import main

    for v in (4.0, 4.2, 6.0):
        add_calibration(tmp_path, "PGA", record(v, 0.1), seed=SEED)
    r = CliRunner().invoke(main, ["library", "list", "--library", str(tmp_path), "--json", str(tmp_path / "l.json")])
    assert r.exit_code == 0, r.output
    rows = {row["family"]: row for row in json.loads((tmp_path / "l.json").read_text())["families"]}
    assert rows["PGA"]["file"] == str(tmp_path / "PGA.toml") and rows["PGA"]["n_flagged"] == 1
    assert rows["PGA"]["equivalent_thickness_m"] == pytest.approx(4.1e-3) and "CQFP" in rows
    png, js = tmp_path / "pga.png", tmp_path / "s.json"
    r = CliRunner().invoke(main, ["library", "show", "PGA", "--library", str(tmp_path), "--plot", str(png), "--json", str(js)])
    assert r.exit_code == 0, r.output
    data = json.loads(js.read_text())
    assert [run["flagged"] for run in data["runs"]] == [False, False, True] and data["pooled"]["n"] == 2
    assert "FLAGGED" in r.output and png.stat().st_size > 10_000
    r = CliRunner().invoke(main, ["library", "show", "BGA", "--library", str(tmp_path)])
    assert r.exit_code == 2 and "family 'BGA' is not in the library" in r.output


def test_pool_of_one_and_of_none():
    assert pool([]) is None
    one = pool([record(4.0, 0.1)])
    assert (one.value, one.std, one.n) == pytest.approx((4e-3, 1e-4, 1))


def test_mesh_part_does_not_average_out():
    """Two runs of std 0.1 mm, 0.08 mm of it their meshes' (fully correlated): the pooled variance keeps
    the whole mesh part, 0.06^2 / 2 + 0.08^2, instead of 0.1^2 / 2 (the other runs' weights are equal). A third run 0.3 mm off on a mesh
    alike differs from them with variance 0.06^2 + 0.06^2 / 2 (the shared mesh error cancels): 4.1
    sigma, flagged; a run without a mesh part (variance 0.1^2 + 0.06^2 / 2 + 0.08^2), 2.2 sigma: kept."""
    from pcbdyn.components.records import judge

    runs = [record(4.0, 0.1, mesh_mm=0.08), record(4.0, 0.1, mesh_mm=0.08)]
    p = pool(runs)
    assert p.std == pytest.approx(math.sqrt(0.06**2 / 2 + 0.08**2) * 1e-3, rel=1e-9) and p.mesh == pytest.approx(8e-5)
    assert "4.1 sigma" in judge(record(4.3, 0.1, mesh_mm=0.08), runs).reason
    assert not judge(record(4.3, 0.1), runs).flagged


def _writer(directory, value, start, go):
    go.wait()
    add_calibration(directory, "PGA", record(value, 0.1, run=f"run{start:02d}"), seed=SEED)


def test_fifty_concurrent_writers_lose_no_record(tmp_path):
    """50 processes released at once add one run each through the real lock: all 50 records are in the
    file, which reads as a valid entry whose value pools them all, and no temporary file is left."""
    ctx = mp.get_context("fork")
    go = ctx.Event()
    procs = [ctx.Process(target=_writer, args=(tmp_path, 4.0 + 0.001 * i, i, go)) for i in range(50)]
    for p in procs:
        p.start()
    go.set()
    for p in procs:
        p.join(120)
    assert all(p.exitcode == 0 for p in procs)
    _, pkg, records = read_entry(tmp_path / "PGA.toml")
    assert sorted(r.run for r in records) == [f"run{i:02d}" for i in range(50)]
    assert not any(r.flagged for r in records)
    assert pkg.equivalent_thickness == pytest.approx(pool(records).value, rel=1e-5)
    assert pkg.equivalent_thickness == pytest.approx(4.0245e-3, rel=1e-5)  # the mean of 4.000 ... 4.049 mm
    assert sorted(p.name for p in tmp_path.iterdir()) == [".PGA.toml.lock", "PGA.toml"]


def _killed_mid_write(directory, marker):
    import pcbdyn.atomic

    def stall(src, dst):  # the new text is written and checked; stop before it replaces the file
        marker.write_text("ready")
        time.sleep(600)

    pcbdyn.atomic.os.replace = stall
    add_calibration(directory, "PGA", record(4.2, 0.1), seed=SEED)


def test_writer_killed_mid_write_leaves_previous_file(tmp_path):
    """SIGKILL while a run holds the lock with its new file written but not yet in place: the previous
    file is byte for byte intact, the lock is free, and the next run writes normally (and clears the
    killed run's temporary file)."""
    add_calibration(tmp_path, "PGA", record(4.0, 0.1), seed=SEED)
    before = (tmp_path / "PGA.toml").read_bytes()
    marker = tmp_path.parent / f"{tmp_path.name}.ready"
    p = mp.get_context("fork").Process(target=_killed_mid_write, args=(tmp_path, marker))
    p.start()
    for _ in range(600):
        if marker.exists():
            break
        time.sleep(0.05)
    assert marker.exists(), "the writer never reached the replace"
    assert any(f.name.startswith(".PGA.") and f.suffix == ".toml" for f in tmp_path.iterdir())  # its new text
    os.kill(p.pid, signal.SIGKILL)
    p.join(10)
    assert p.exitcode == -signal.SIGKILL
    assert (tmp_path / "PGA.toml").read_bytes() == before
    with FileLock(lock_path(tmp_path, "PGA"), timeout=0):  # the killed run's lock is free at once
        pass
    _, _, n = add_calibration(tmp_path, "PGA", record(4.1, 0.1), seed=SEED)
    assert n == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == [".PGA.toml.lock", "PGA.toml"]


@pytest.mark.parametrize("text,field", [
    ("[package\nname = 1", "not valid TOML"),
    ('[package]\nname = "PGA"\nsize = ["40 mm", "40 mm"]\nheight = "2 mm"\nmass = "14 g"\n'
     'default_model = "equivalent_thickness"\nequivalent_thickness = "3.5 mm"\n\n[[calibrations]]\nrun = "a"\n'
     'date = 2026-01-01T00:00:00Z\nmethod = "freq"\nvalue = "4 mm"\nbefore = "3.5 mm"\nflagged = false\n',
     "calibrations[0].std"),
])
def test_malformed_library_file_is_refused_untouched(tmp_path, text, field):
    path = tmp_path / "PGA.toml"
    path.write_text(text)
    with pytest.raises(LibraryError, match=field.replace("[", r"\[").replace("]", r"\]")):
        add_calibration(tmp_path, "PGA", record(4.0, 0.1), seed=SEED)
    assert path.read_text() == text
