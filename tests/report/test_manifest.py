"""An output folder holds only the last run's files and is replaced whole: the files an earlier run wrote and
this one did not are gone, never a file pcbdyn did not write or one changed since; a run interrupted while it
writes leaves the earlier folder exactly as it was, its manifest matching its files."""

import hashlib
import json
import os

import pytest

from pcbdyn.report.files import write_text
from pcbdyn.report.manifest import MANIFEST, replacing


def files(out) -> list:
    return sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())


def matches_its_manifest(out) -> bool:
    listed = json.loads((out / MANIFEST).read_text())["files"]
    return all(hashlib.sha256((out / rel).read_bytes()).hexdigest() == d for rel, d in listed.items())


def run_writing(out, names, command="test"):
    with replacing(out, command) as run:
        for name in names:
            write_text(run.path / name, name)
    return run


def test_a_smaller_run_removes_only_the_earlier_runs_own_unchanged_files(tmp_path):
    out = tmp_path / "out"
    assert run_writing(out, ["a.csv", "b.csv", "png/m_01.png", "png/m_02.png", "old/x.png"]).removed == []
    write_text(out / "notes.txt", "mine")  # the user's, beside pcbdyn's files
    write_text(out / "png" / "sketch.png", "mine")
    write_text(out / "b.csv", "edited by hand")  # pcbdyn wrote it, the user changed it since
    (out / "empty").mkdir()
    run = run_writing(out, ["a.csv", "png/m_01.png"])
    assert run.removed == ["old/x.png", "png/m_02.png"]
    assert files(out) == sorted(["a.csv", "b.csv", MANIFEST, "notes.txt", "png/m_01.png", "png/sketch.png"])
    assert (out / "empty").is_dir() and not (out / "old").exists()
    assert sorted(json.loads((out / MANIFEST).read_text())["files"]) == ["a.csv", "png/m_01.png"]
    assert matches_its_manifest(out) and (out / "b.csv").read_text() == "edited by hand"
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging folder left beside it


def test_an_interrupted_run_leaves_the_earlier_folder_as_it_was(tmp_path):
    out = tmp_path / "out"
    run_writing(out, ["a.csv", "png/m_01.png", "png/m_02.png"])
    write_text(out / "notes.txt", "mine")
    before = {rel: (out / rel).read_bytes() for rel in files(out)}
    inode = os.stat(out).st_ino
    with pytest.raises(KeyboardInterrupt):
        with replacing(out, "test") as run:
            write_text(run.path / "a.csv", "new")
            write_text(run.path / "png" / "m_01.png", "new")
            raise KeyboardInterrupt  # Ctrl-C while the pictures are drawn
    assert {rel: (out / rel).read_bytes() for rel in files(out)} == before
    assert os.stat(out).st_ino == inode and matches_its_manifest(out)
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_a_manifest_pointing_outside_the_folder_removes_nothing_there(tmp_path):
    out = tmp_path / "out"
    outside = tmp_path / "precious.txt"
    outside.write_text("keep")
    digest = hashlib.sha256(b"keep").hexdigest()
    write_text(out / MANIFEST, json.dumps({"files": {"../precious.txt": digest, str(outside): digest}}))
    assert run_writing(out, []).removed == []
    assert outside.read_text() == "keep"
    write_text(out / MANIFEST, "not json")
    assert run_writing(out, []).removed == []


def test_a_folder_of_the_users_or_the_current_one_is_not_replaced(tmp_path, monkeypatch):
    from pcbdyn.report.manifest import unreplaceable

    mine = tmp_path / "mine"
    write_text(mine / "thesis.pdf", "x")
    assert "no pcbdyn-manifest.json" in unreplaceable(mine)
    monkeypatch.chdir(mine)
    assert "current folder" in unreplaceable(".") and "current folder" in unreplaceable(tmp_path)
    run_writing(tmp_path / "out", ["a.csv"])
    for ok in (tmp_path / "out", tmp_path / "new", tmp_path / "empty"):
        assert unreplaceable(ok) is None
