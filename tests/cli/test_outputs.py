"""What a run writes and where (issue 21): output places checked before any work, ``--json -`` on the
standard output, results in ``--out`` and never over an earlier file beside the input without saying
so, and update's status in the user's terms. Each of these failed before the change."""

import json
import re
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from pcbdyn.cli import main

ROOT = Path(__file__).resolve().parents[2]
CARD = ROOT / "examples" / "six_part_card"
TABLE = CARD / "measured_frequencies_table_7_2.csv"


def run(args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture
def card(tmp_path):
    shutil.copy(CARD / "board.toml", tmp_path / "board.toml")
    return tmp_path / "board.toml"


@pytest.mark.parametrize("option", ["--json", "--out"])
def test_an_output_under_a_file_is_refused_before_any_work(card, tmp_path, option):
    (tmp_path / "a_file").write_text("x")
    target = tmp_path / "a_file" / ("r.json" if option == "--json" else "dir")
    r = run(["update", card, "--frequencies", TABLE, "--max-iter", "1", option, target])
    assert r.exit_code == 2
    assert "a_file is a file, not a folder" in r.output and "building the models" not in r.output


def test_json_dash_writes_json_alone_on_stdout(card):
    r = run(["build", card, "--no-pictures", "--json", "-"])
    assert r.exit_code == 0, r.output
    data = json.loads(r.stdout)
    assert [m["n"] for m in data["modes"]] == list(range(1, 8)) and not (card.parent / "-").exists()
    assert "frequency [Hz]" in r.stderr  # the table goes to stderr


def test_a_study_whose_out_is_a_file_fails_before_the_shots(tmp_path):
    """``study`` takes ``--out`` like every command (it wrote where its study.toml's ``out`` said, beside the
    example); an ``out`` left in the file is refused with the fix."""
    (tmp_path / "taken").write_text("x")
    spec = tmp_path / "study.toml"
    spec.write_text('[study]\ncase = "simulated_free_pcb"\nlevels_pct = [0]\nshots = 1\n')
    r = run(["study", spec, "--quiet", "--out", tmp_path / "taken"])
    assert r.exit_code == 2 and "--out" in r.output and "is a file" in r.output and "building case" not in r.output
    spec.write_text('[study]\ncase = "simulated_free_pcb"\nlevels_pct = [0]\nshots = 1\nout = "taken"\n')
    r = run(["study", spec, "--quiet"])
    assert r.exit_code == 2 and "study.out" in r.output and "--out DIR" in r.output and "Traceback" not in r.output


def test_update_on_the_thesis_data_says_the_model_cannot_fit(card, tmp_path):
    """Table 7.2 data, four parameters (issue 40): the card's model cannot fit its test within the noise
    (chi^2 far above its degrees of freedom; with the mesh error in the noise it is still 3184 over 19),
    E_board ends on its bound and configuration c3 ends worse than it started: the status says so instead
    of "converged", and no updated board is written without --force (the page is)."""
    js = tmp_path / "u.json"
    r = run(["update", card, "--frequencies", TABLE, "--out", tmp_path / "out", "--json", js, "--no-mesh-check",
             "--html"])
    assert r.exit_code == 0, r.output
    data = json.loads(js.read_text())
    assert data["status"] == "cannot fit" and not data["verdict"]["fits"]
    assert data["verdict"]["chi2"] > 10 * data["verdict"]["dof"] and data["verdict"]["dof"] == 23 - 4
    page = (tmp_path / "out" / "report.html").read_text()  # the page animates the updated model's modes
    assert 'data-title="Parameters"' in page and 'data-title="Correlation before and after"' in page
    view = json.loads(re.search(r'class="view-data">(.*?)</script>', page, re.S).group(1))
    base = next(c for c in data["after"]["configurations"] if c["configuration"] == "base")
    assert view["labels"][0] == f"mode 1: {base['pairs'][0]['f_model_hz']:.1f} Hz"
    details = " ".join(data["status_details"])
    assert "the model cannot fit the test: chi^2" in details and "E_board stopped at its upper bound" in details
    assert "configuration c3: max |df| grew" in details
    assert "cannot fit after" in r.output and "note: the model cannot fit the test" in r.output
    assert "iteration 1:" in r.output and "on 3 test configuration(s)" in r.output
    assert all(h["condition_stacked"] is None or h["condition_stacked"] > 0 for h in data["history"])
    assert data["updated_board"] is None and not (tmp_path / "out" / "board.updated.toml").exists()
    assert "no updated board written" in r.output
    forced = run(["update", card, "--frequencies", TABLE, "--out", tmp_path / "forced", "--force", "--max-iter", "1",
                  "--no-mesh-check"])
    assert forced.exit_code == 0 and (tmp_path / "forced" / "board.updated.toml").exists()


def own_frequencies(card, tmp_path, t_pga: float) -> Path:
    """A frequency table of the card's own model with t_PGA = ``t_pga`` [m] (its first five elastic modes):
    a test the model fits."""
    from pcbdyn.board import load_board
    from pcbdyn.problems import UpdateProblem
    from pcbdyn.updating import frequencies_hz, pencil_modes

    sysm = UpdateProblem(load_board(card), ["t_PGA"]).system(None)
    K, M, _, _ = sysm.model([t_pga])
    f = frequencies_hz(pencil_modes(K, M, sysm.n_rigid + 5)[0])[sysm.n_rigid:]
    path = tmp_path / "own.csv"
    path.write_text("configuration,mode,frequency_hz\n" + "".join(f"c1,{i + 1},{v:.4f}\n" for i, v in enumerate(f)))
    return path


def test_an_earlier_updated_board_beside_the_input_is_kept(card, tmp_path):
    args = ["update", card, "--frequencies", own_frequencies(card, tmp_path, 3.3e-3), "--params", "t_PGA",
            "--no-mesh-check"]
    r = run(args)
    assert r.exit_code == 0 and "converged after" in r.output, r.output
    first = (card.parent / "board.updated.toml").read_text()
    r = run(args)
    assert r.exit_code == 0 and "board.updated.2.toml" in r.output
    assert (card.parent / "board.updated.toml").read_text() == first
    assert run(args + ["--force"]).exit_code == 0 and not (card.parent / "board.updated.3.toml").exists()


def test_help_shows_the_name_file_syntax_and_the_choices():
    for cmd in ("update", "localize", "diagnose"):
        assert "NAME=FILE" in run([cmd, "--help"]).output
    assert "point_mass, point_inertia, ground_spring" in re.sub(r"\s+", " ", run(["diagnose", "--help"]).output)


@pytest.mark.parametrize("size,expect", [("60 mm", "elements across"), ("0.3 mm", "DOFs, more than the limit")])
def test_a_mesh_size_far_off_the_board_gets_the_estimate(card, size, expect):
    text = card.read_text().replace('mesh_size = "6.75 mm"', f'mesh_size = "{size}"')
    card.write_text(text)
    r = run(["build", card, "--no-pictures"])
    assert r.exit_code == 2 and expect in r.output and "board.mesh_size" in r.output


def test_a_bug_is_one_line_with_a_log_not_a_traceback(card, monkeypatch):
    import pcbdyn.problems

    def broken(path):
        raise RuntimeError("something inside broke")

    monkeypatch.setattr(pcbdyn.problems, "load_structure", broken)
    r = run(["build", card, "--no-pictures"])
    assert r.exit_code == 3 and "Traceback" not in r.output
    line = r.output.strip()
    assert "internal error (a bug in pcbdyn" in line and "\n" not in line
    log = Path(line.rsplit("the traceback is in ", 1)[1])
    assert "something inside broke" in log.read_text() and "Traceback" in log.read_text()


def test_a_modulus_is_printed_in_gpa(card, tmp_path):
    """The parameter table printed E_board as 2.6e+10 Pa; it prints 26 GPa (the JSON keeps SI values)."""
    js = tmp_path / "u.json"
    r = run(["update", card, "--frequencies", TABLE, "--params", "E_board", "--max-iter", "1", "--out",
             tmp_path / "out", "--json", js])
    assert r.exit_code == 0, r.output
    assert re.search(r"E_board\s+GPa\s+26\s+\d+\.\d+", r.output), r.output
    e = json.loads(js.read_text())["parameters"]["E_board"]
    assert (e["unit"], e["display_unit"], e["initial"]) == ("Pa", "GPa", 26e9)


def test_a_folder_that_is_not_pcbdyns_is_refused_as_out_before_any_work(card, tmp_path):
    """--out replaces its folder whole: the board's own folder (files, no manifest) is refused, untouched."""
    before = sorted(p.name for p in tmp_path.iterdir())
    r = run(["update", card, "--frequencies", TABLE, "--max-iter", "1", "--out", tmp_path])
    assert r.exit_code == 2 and "not an output folder of pcbdyn" in r.output and "building the models" not in r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == before
