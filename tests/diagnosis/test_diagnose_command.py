"""`pcbdyn diagnose` refuses bad input before any work, naming the option or file and the fix."""

from pathlib import Path

from click.testing import CliRunner

from pcbdyn.cli import main

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"


def heavy_card_test(path):
    """A modal test of the six-part card (88 g) carrying an undeclared 40 g mass, written to ``path`` (UFF):
    seven modes at the card's points, noise 0.2 % on the frequencies and 2 % on the shapes."""
    from pcbdyn.board import load_board
    from pcbdyn.fe.modal import solve_modes
    from pcbdyn.testdata import read_points_csv, write_uff
    from pcbdyn.testdata.noise import Noise
    from pcbdyn.testdata.simulate import simulate_on_model

    heavy = path.with_suffix(".toml")
    heavy.write_text((CARD / "board.toml").read_text() + '\n[[masses]]\nname = "extra"\nat = ["120 mm", "150 mm"]\n'
                                                          'mass = "40 g"\n')
    truth = load_board(heavy).build().model
    points, dofs = read_points_csv(CARD / "points.csv")
    write_uff(path, simulate_on_model(truth, solve_modes(truth, n_modes=7), points, dofs,
                                      noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=3))


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


def test_an_internal_error_still_writes_what_was_computed(tmp_path, monkeypatch):
    """A bug in a later step (here: the candidates cannot be generated) ends the command with the
    one-line internal error, and the JSON holds what was computed before it (the correlation as given
    and with the declared parameters fitted), marked incomplete, with the error; so does a model error
    met on the way (discovery report seed 1001 had stopped on an indefinite stiffness with no JSON). A
    ValueError raised inside the diagnosis is a bug too, not bad input (it used to exit 2 as if it were)."""
    import json

    from pcbdyn.diagnosis import pipeline
    from pcbdyn.fe.model import ModelError

    heavy_card_test(tmp_path / "t.uff")

    for error, code in ((RuntimeError("a bug in the candidates"), 3), (ValueError("a candidate misses the plate"), 3),
                        (ModelError("negative eigenvalue -2.3e+08: the stiffness matrix is not positive"), 2)):
        def broken(*args, **kwargs):
            raise error

        monkeypatch.setattr(pipeline, "generate", broken)
        js = tmp_path / f"d{code}.json"
        r = run(CARD / "board.toml", tmp_path / "t.uff", "--quick", "--workers", "1", "--json", js)
        assert r.exit_code == code and str(error) in r.output
        data = json.loads(js.read_text())
        assert data["complete"] is False and type(error).__name__ in data["error"]
        assert data["before"]["max_freq_error_pct"] > data["parameters_only"]["max_freq_error_pct"] > 0.5
