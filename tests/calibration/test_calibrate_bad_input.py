"""Bad input to ``pcbdyn calibrate``: a family not on the board, a family not in the library, a
malformed library file, a test of another board (MAC pairing fails), bad calibration files. Each
gives a clear error naming what is wrong, and the library folder is left as it was."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from pcbdyn.cli import main
from pcbdyn.components.library import shipped_library

from sim_boards import board_text, simulated_test

CLAMPED = '\n[[fixtures]]\ntype = "clamped_edge"\nedge = "x=0"\n'


def snapshot(d):
    return {p.name: p.read_bytes() for p in d.iterdir()} if d.exists() else None


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """b1 at a coarse mesh with its own simulated test, a library folder holding a calibrated-looking
    PGA entry (copied from the shipped one), and the same board clamped on one edge (another board)."""
    d = tmp_path_factory.mktemp("bad")
    board = d / "b1.toml"
    board.write_text(board_text("b1", 10.0))
    clamped = d / "clamped.toml"
    clamped.write_text(board_text("b1", 10.0) + CLAMPED)
    test = simulated_test(board, d / "b1.uff", "b1")
    return d, board, test, clamped


def run(args, lib):
    before = snapshot(lib)
    r = CliRunner().invoke(main, ["calibrate", *map(str, args), "--library", str(lib)])
    assert r.exit_code == 2, r.output
    assert snapshot(lib) == before
    return r.output


def library(tmp_path, pga_text=None):
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "PGA.toml").write_text(pga_text or (shipped_library() / "PGA.toml").read_text())
    return lib


def test_family_not_on_the_board(case, tmp_path):
    d, board, test, _ = case
    text = board.read_text().replace('package = "CQFP"', 'package = "JLCC"')
    (d / "no_cqfp.toml").write_text(text)
    out = run([d / "no_cqfp.toml", test, "--families", "PGA,CQFP"], library(tmp_path))
    assert "no part of no_cqfp.toml is of family 'CQFP'" in out and "families on the board: PGA, JLCC" in out


def test_family_not_in_the_library(case, tmp_path):
    _, board, test, _ = case
    out = run([board, test, "--families", "PGA,BGA"], library(tmp_path))
    assert "family 'BGA' is not in the library" in out and "lib" in out


def test_malformed_library_file(case, tmp_path):
    _, board, test, _ = case
    out = run([board, test], library(tmp_path, "[package\nname = 'PGA'\n"))
    assert "PGA.toml" in out and "not valid TOML" in out and "components[0].package" in out


def test_malformed_calibration_record(case, tmp_path):
    _, board, test, _ = case
    text = (shipped_library() / "PGA.toml").read_text() + ('\n[[calibrations]]\nrun = "x"\ndate = 2026-01-01T00:00:00Z\n'
                                                           'method = "freq"\nvalue = "4 mm"\nstd = "-1 mm"\n'
                                                           'before = "3.5 mm"\nflagged = false\n')
    out = run([board, test], library(tmp_path, text))
    assert "PGA.toml: calibrations[0].std: must be a positive length" in out


def test_test_of_another_board(case, tmp_path):
    """The free board's test given for the same board clamped on an edge: its modes do not pair."""
    _, _, test, clamped = case
    out = run([clamped, test], library(tmp_path))
    assert "b1.uff" in out and "pair with the model's by MAC" in out and "is it a test of this board?" in out


def test_bad_joint_file(case, tmp_path):
    d, board, test, _ = case
    joint = d / "joint.toml"
    lib = library(tmp_path)
    joint.write_text(f'[[boards]]\nboard = "{board.name}"\ntset = "{test.name}"\n')
    out = run(["--joint", joint], lib)
    assert "joint.toml: boards[0].tset: unknown field; did you mean 'test'?" in out
    joint.write_text(f'[[boards]]\nboard = "{board.name}"\ntest = "missing.uff"\n')
    out = run(["--joint", joint], lib)
    assert "boards[0].test: 'missing.uff': no such file" in out
