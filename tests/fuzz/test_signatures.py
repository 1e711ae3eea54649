"""The failure signatures issue 22 lists, each as a regression test through entry points main (a67c95f) had
too (load_board, build_model, read_package, read_uff, read_points_csv, to_si, pair_modes, atomic_path, the
CLI), so that running this file against main shows each one failing there: a crash, a hang, an invalid
input read without a word, a message that names no file, or a result file lost or half-written.
Reader-level signatures are the files of tests/fuzz/corpus."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import pcbdyn
from pcbdyn.cli import main

CORPUS = Path(__file__).resolve().parent / "corpus"
ROOT = Path(__file__).resolve().parents[2]
BOARD = ROOT / "tests" / "data" / "boards" / "bad_input_good.toml"
PACKAGE_ROOT = str(Path(pcbdyn.__file__).resolve().parents[1])  # the pcbdyn under test, for child processes


def _refused(read, path: Path, name: str | None = None):
    """``read(path)`` raises one of pcbdyn's input errors (a ValueError), in one line naming the file."""
    with pytest.raises(ValueError) as err:
        read(path)
    msg = str(err.value)
    assert (name or path.name) in msg and "\n" not in msg, msg
    return msg


def _readers():
    from pcbdyn.board import load_board
    from pcbdyn.components.library import read_package
    from pcbdyn.testdata import read_points_csv, read_uff

    return {"board": load_board, "library": read_package, "uff": read_uff, "points": read_points_csv}


CASES = sorted(p.relative_to(CORPUS).as_posix() for kind in ("board", "library", "uff", "points")
               for p in (CORPUS / kind).glob("*") if not p.name.startswith("ok-"))


@pytest.mark.parametrize("rel", CASES)
def test_corpus_input_is_refused_naming_the_file(rel):
    """Non-UTF-8 files (UnicodeDecodeError before), an empty target list (IndexError), an outline with a
    repeated vertex (gmsh's bare Exception at build), a 300-character package name (OSError), a
    400-digit number (OverflowError), k_rot = "inf ..." (ValueError in the eigensolver), a zero unit
    factor (ZeroDivisionError), and inputs read silently before: "1,6 mm", a bare "mm", "13 g#",
    negative or zero library values, test frequencies at or below 0, NaN or 1e300 shape values, node ids
    twice, analysis.modes = 1000, NaN in a points CSV."""
    path = CORPUS / rel
    _refused(_readers()[path.parent.name], path)


def _child(code: str, timeout: float) -> subprocess.CompletedProcess:
    """``code`` in a fresh Python on the pcbdyn under test; a hang is a test failure, not a stuck suite."""
    env = {**os.environ, "PYTHONPATH": PACKAGE_ROOT, "OPENBLAS_NUM_THREADS": "1"}
    try:
        return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, capture_output=True,
                              text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail(f"no answer within {timeout:g} s (a hang)")


def test_a_tiny_mesh_size_ends_at_once_with_an_estimate(tmp_path):
    """mesh_size = "1 um" sent gmsh into a hang; now the DOF estimate refuses it before meshing."""
    board = tmp_path / "board.toml"
    board.write_text(BOARD.read_text().replace('mesh_size = "10 mm"', 'mesh_size = "1 um"'))
    r = _child(f"""
        from pcbdyn.board import BoardError, build_model, load_board
        try:
            build_model(load_board({str(board)!r}))
        except BoardError as exc:
            print(exc)
        """, 120)
    assert "board.toml: board.mesh_size" in r.stdout and "DOFs" in r.stdout, r.stdout + r.stderr


def _card(tmp_path) -> Path:
    """The six-part card at a coarse mesh (13.5 mm: fast), as board.toml in ``tmp_path``."""
    text = (ROOT / "examples" / "six_part_card" / "board.toml").read_text()
    assert 'mesh_size = "6.75 mm"' in text
    (tmp_path / "board.toml").write_text(text.replace('mesh_size = "6.75 mm"', 'mesh_size = "13.5 mm"'))
    return tmp_path / "board.toml"


def test_gmsh_is_stopped_at_its_time_limit(tmp_path):
    """gmsh ran in-process without a limit (a hang on a mesh it cannot finish); now it runs in a child
    that is killed at PCBDYN_MESH_TIMEOUT, and the build ends with one error line naming board.toml."""
    board = _card(tmp_path)
    env = {**os.environ, "PYTHONPATH": PACKAGE_ROOT, "OPENBLAS_NUM_THREADS": "1", "PCBDYN_MESH_TIMEOUT": "0.001"}
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-c", "from pcbdyn.cli import main; main()", "build", str(board),
                        "--no-pictures"], env=env, capture_output=True, text=True, timeout=120)
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("error:")]
    assert r.returncode == 2 and len(errors) == 1, r.stdout + r.stderr
    assert "board.toml" in errors[0] and "PCBDYN_MESH_TIMEOUT" in errors[0], errors[0]
    assert time.monotonic() - t0 < 60


def test_quantities_that_hung_end_at_once():
    """A 100k-character number and 9**9**9 (pint evaluates the power tower) hung to_si."""
    r = _child("""
        from pcbdyn.units import UnitError, to_si
        for text in ("1" + "0" * 100_000 + " mm", "9**9**9 mm"):
            try:
                print("read", to_si(text, "mm", "b.toml: x"))
            except UnitError as exc:
                print("refused", str(exc)[:60])
        """, 30)
    assert r.stdout.count("refused") == 2, r.stdout + r.stderr


@pytest.mark.parametrize("text", ["100,5 mm", "mm", "12 mm#", "9" * 400 + " mm", "12 mm 3"])
def test_malformed_quantities_are_refused_not_misread(text):
    """pint read "100,5 mm" as 1005 mm, a bare "mm" as 1 mm and ignored junk; a 400-digit number overflowed."""
    from pcbdyn.units import UnitError, to_si

    with pytest.raises(UnitError, match="b.toml: x"):
        to_si(text, "mm", "b.toml: x")


def test_huge_shapes_pair_by_mac():
    """pair_modes raised ValueError on shapes of 1e200 (their squares overflow); the MAC does not depend
    on scale, so they pair as the same shapes at scale 1 do."""
    from pcbdyn.correlation.pairing import pair_modes

    rng = np.random.default_rng(0)
    A = rng.standard_normal((20, 4))
    p = pair_modes(A[:, :3] * 1e200, A, [100.0, 200.0, 300.0], [101.0, 199.0, 305.0, 400.0])
    assert [(q.test, q.model) for q in p.pairs] == [(0, 0), (1, 1), (2, 2)]
    assert all(q.mac == pytest.approx(1.0) for q in p.pairs)


def test_a_shell_without_mass_is_named_with_its_file(tmp_path):
    """"shell property mass_per_area() must be > 0" named no file and no field (rho * t underflows)."""
    board = tmp_path / "board.toml"
    shutil.copy(CORPUS / "board" / "mass-per-area-zero.toml", board)
    r = CliRunner().invoke(main, ["build", str(board), "--no-pictures"])
    errors = [ln for ln in r.output.splitlines() if ln.startswith("error:")]
    assert r.exit_code == 2 and len(errors) == 1 and "board.toml: board." in errors[0], r.output


def test_update_json_is_json_when_the_condition_number_is_infinite(tmp_path):
    """One measured frequency for the card's parameters: the stacked equations have more columns than rows,
    their condition number is infinite, and update wrote 'Infinity' (not JSON) into history[]."""
    board = _card(tmp_path)
    (tmp_path / "f.csv").write_text("configuration,mode,frequency_hz\nbase,1,214.16\n")
    r = CliRunner().invoke(main, ["update", str(board), "--frequencies", str(tmp_path / "f.csv"), "--max-iter", "1",
                                  "--json", str(tmp_path / "u.json"), "--out", str(tmp_path / "u")])
    assert r.exit_code == 0, r.output

    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    data = json.loads((tmp_path / "u.json").read_text(), parse_constant=refuse)
    assert data["history"][0]["condition_stacked"] is None


def _digests(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_failed_savefig_leaves_the_earlier_iterations_png(tmp_path, monkeypatch):
    """iterations.png was saved in place: a run stopped while saving it left it emptied (2 of 14 kills)."""
    import matplotlib.figure

    board = _card(tmp_path)
    table = ROOT / "examples" / "six_part_card" / "measured_frequencies_table_7_2.csv"
    args = ["update", str(board), "--frequencies", str(table), "--max-iter", "1", "--out", str(tmp_path / "u")]
    assert CliRunner().invoke(main, args).exit_code == 0
    before = (tmp_path / "u" / "iterations.png").read_bytes()

    def stopped(self, fname, *a, **k):  # half a picture, then the run dies
        with open(fname, "wb") as fh:
            fh.write(b"\x89PNG half")
        raise KeyboardInterrupt

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", stopped)
    CliRunner().invoke(main, args)
    assert (tmp_path / "u" / "iterations.png").read_bytes() == before
    assert not [p.name for p in (tmp_path / "u").iterdir() if p.name.startswith(".")]


def test_a_multi_configuration_build_that_fails_writes_nothing(tmp_path, monkeypatch):
    """build --all-configs failing at c3 had already rewritten the base results beside the old JSON."""
    import pcbdyn.board.model as model

    board = _card(tmp_path)
    out = tmp_path / "out"
    args = ["build", str(board), "--all-configs", "--no-pictures", "--out", str(out), "--json", str(out / "m.json")]
    assert CliRunner().invoke(main, args).exit_code == 0
    before = _digests(out)
    board.write_text(board.read_text().replace('mass = "53.2 g"', 'mass = "60 g"'))  # the next results differ
    meshes = []
    real = model.mesh_board

    def third_fails(*a, **k):
        meshes.append(1)
        if len(meshes) == 3:
            raise RuntimeError("c3 cannot be meshed")
        return real(*a, **k)

    monkeypatch.setattr(model, "mesh_board", third_fails)
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 2 and "c3 cannot be meshed" in r.output, r.output
    assert _digests(out) == before


def _stopped_writer(folder: Path, name: str) -> int:
    """pid of a forked process stopped half-way through an atomic write of ``folder/name``."""
    from pcbdyn.atomic import atomic_path

    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(r)
        with atomic_path(folder / name) as tmp:
            tmp.write_text("mode,frequency\n1,")
            os.write(w, b"x")
            time.sleep(60)
        os._exit(0)
    os.close(w)
    assert os.read(r, 1) == b"x"
    os.close(r)
    return pid


def _hidden_after_kill(folder: Path, pid: int, stays: int) -> list:
    """Kill ``pid`` and wait (at most 10 s) until ``folder`` holds only ``stays`` hidden files."""
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    t_end = time.monotonic() + 10
    while True:
        hidden = sorted(p.name for p in folder.iterdir() if p.name.startswith("."))
        if len(hidden) <= stays or time.monotonic() > t_end:
            return hidden
        time.sleep(0.02)


def test_a_killed_writer_leaves_no_temporary_file(tmp_path):
    """A run killed while writing left its hidden temporary file for good (22 of 133 kills); now it is
    gone right after the kill, with no further write into the folder, while a live writer's file stays."""
    first = _stopped_writer(tmp_path, "modes.csv")
    second = _stopped_writer(tmp_path, "other.csv")
    assert len([p for p in tmp_path.iterdir() if p.name.startswith(".")]) == 2  # both half-written
    left = _hidden_after_kill(tmp_path, first, stays=1)
    assert len(left) == 1 and left[0].startswith(".other."), left
    assert _hidden_after_kill(tmp_path, second, stays=0) == []
    assert list(tmp_path.iterdir()) == []


def _children(pid: int, marker: str) -> list:
    """Live descendants of ``pid`` whose command line holds ``marker``."""
    from processes import descendants

    out = []
    for c in descendants(pid):
        try:
            if marker in Path(f"/proc/{c}/cmdline").read_bytes().decode(errors="replace"):
                out.append(c)
        except OSError:
            continue
    return out


def test_the_picture_renderer_dies_with_a_killed_build(tmp_path):
    """The pyvista renderer (a child process) outlived a killed build by up to 2 s; now it dies with it."""
    from processes import alive
    board = _card(tmp_path)
    env = {**os.environ, "PYTHONPATH": PACKAGE_ROOT, "OPENBLAS_NUM_THREADS": "1"}
    build = subprocess.Popen([sys.executable, "-c", "from pcbdyn.cli import main; main()", "build", str(board),
                              "--out", str(tmp_path / "out")], env=env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    try:
        t_end, renderer = time.monotonic() + 180, []
        while not renderer and build.poll() is None and time.monotonic() < t_end:
            renderer = _children(build.pid, "render_pyvista")
            time.sleep(0.02)
        if not renderer:
            pytest.skip("the build started no renderer process")
        build.kill()
        build.wait()
        time.sleep(0.3)
        assert not [p for p in renderer if alive(p)], "the renderer outlived the killed build"
    finally:
        build.kill()
        build.wait()
        for p in renderer:  # the renderer this test's build started, should it have survived
            if alive(p):
                os.kill(p, signal.SIGKILL)
