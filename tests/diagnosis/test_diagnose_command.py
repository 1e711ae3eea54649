"""`pcbdyn diagnose` refuses bad input before any work, naming the option or file and the fix."""

from pathlib import Path

from click.testing import CliRunner

from pcbdyn.cli import main

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"


def run(*args):
    return CliRunner().invoke(main, ["diagnose", *map(str, args)])


def test_bad_options_and_configurations(tmp_path):
    uff = tmp_path / "t.uff"
    uff.write_text("    -1\n    55\n")
    r = run(CARD / "board.toml", uff, "--noise", "loud")
    assert r.exit_code == 2 and "--noise" in r.output and "f=0.2,shape=2" in r.output
    r = run(CARD / "board.toml", uff, "--kinds", "point_mass,ghost")
    assert r.exit_code == 2 and "ghost" in r.output and "ground_spring" in r.output
    r = run(CARD / "board.toml", uff, "c9=" + str(uff))
    assert r.exit_code == 2 and "t.uff" in r.output  # the malformed UFF is named before the configuration
    r = run(CARD / "board.toml", uff, "c2")
    assert r.exit_code == 2 and "NAME=FILE" in r.output
