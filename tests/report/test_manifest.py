"""An output folder holds only the last run's files: the files an earlier run wrote and this one
did not are deleted, never a file pcbdyn did not write or one changed since."""

import hashlib
import json

from pcbdyn.report.files import write_text
from pcbdyn.report.manifest import MANIFEST, settle


def test_a_smaller_run_removes_only_the_earlier_runs_own_unchanged_files(tmp_path):
    out = tmp_path / "out"
    first = [out / "a.csv", out / "b.csv", out / "png" / "m_01.png", out / "png" / "m_02.png", out / "old" / "x.png"]
    for p in first:
        write_text(p, p.name)
    assert settle(out, first, "test") == []
    write_text(out / "notes.txt", "mine")  # the user's, beside pcbdyn's files
    write_text(out / "png" / "sketch.png", "mine")
    write_text(out / "b.csv", "edited by hand")  # pcbdyn wrote it, the user changed it since
    second = [out / "a.csv", out / "png" / "m_01.png"]
    removed = settle(out, second, "test")
    assert removed == ["old/x.png", "png/m_02.png"]
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted([
        "a.csv", "b.csv", MANIFEST, "notes.txt", "png/m_01.png", "png/sketch.png"])
    assert not (out / "old").exists()  # emptied by the removal
    assert sorted(json.loads((out / MANIFEST).read_text())["files"]) == ["a.csv", "png/m_01.png"]


def test_a_manifest_pointing_outside_the_folder_removes_nothing_there(tmp_path):
    out = tmp_path / "out"
    outside = tmp_path / "precious.txt"
    outside.write_text("keep")
    digest = hashlib.sha256(b"keep").hexdigest()
    write_text(out / MANIFEST, json.dumps({"files": {"../precious.txt": digest, str(outside): digest}}))
    assert settle(out, [], "test") == []
    assert outside.read_text() == "keep"
    write_text(out / MANIFEST, "not json")
    assert settle(out, [], "test") == []
