"""Reading a study.toml (pcbdyn.problems.study_spec): every case of pcbdyn.problems.cases.CASES is read with
the options its class declares."""

from pathlib import Path

import pytest

from pcbdyn.problems.cases import CASES, StructureCase
from pcbdyn.problems.study_spec import StudyError, read_spec

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card"


@pytest.mark.parametrize("case", ["board", "structure"])
def test_a_structure_case_reads_its_truth_in_si(tmp_path, case):
    """Both names of the structure case (``structure`` raised a KeyError when the options were a table of
    the command's keyed by case name): the [truth] thickness 4.5 mm is 4.5e-3 m, the card loaded once."""
    (tmp_path / "study.toml").write_text(
        f'[study]\ncase = "{case}"\nboard = "{CARD}/board.toml"\npoints = "{CARD}/points.csv"\n'
        '[truth]\nt_PGA = "4.5 mm"\n[case]\nn_modes = 4\n')
    spec = read_spec(tmp_path / "study.toml")
    opts = spec["case_options"]
    assert CASES[case] is StructureCase and opts["truth"] == {"t_PGA": pytest.approx(4.5e-3, rel=1e-12)}
    assert opts["n_modes"] == 4 and opts["structure"].path == CARD / "board.toml"


def test_an_option_of_another_case_is_named_with_the_fix(tmp_path):
    (tmp_path / "study.toml").write_text(f'[study]\ncase = "board"\nboard = "{CARD}/board.toml"\n'
                                         f'points = "{CARD}/points.csv"\n[truth]\nt_PGA = "4.5 mm"\n[case]\nnu = 0.3\n')
    with pytest.raises(StudyError, match=r"study.toml: case.nu: unknown field; allowed: n_modes, params"):
        read_spec(tmp_path / "study.toml")
