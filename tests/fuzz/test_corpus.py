"""Every input of tests/fuzz/corpus (README there) is refused with one clean line naming the file, or, for
``ok-*`` files, read with every number finite."""

from pathlib import Path

import pytest

from fuzz_kinds import _read_library, _read_uff, six_part_card
from fuzz_outcome import classify

CORPUS = Path(__file__).resolve().parent / "corpus"


def _reader(kind):
    from pcbdyn.board import load_board
    from pcbdyn.ecad.packages import read_map
    from pcbdyn.problems.study_spec import read_spec
    from pcbdyn.testdata import read_points_csv
    from pcbdyn.testdata.measured import read_frequency_table

    return {"board": load_board, "library": _read_library, "uff": _read_uff, "points": read_points_csv,
            "frequencies": lambda p: read_frequency_table(p, six_part_card()), "map": read_map, "study": read_spec}[kind]


FILES = sorted(p.relative_to(CORPUS).as_posix() for p in CORPUS.glob("*/*") if p.is_file())


@pytest.mark.parametrize("rel", FILES)
def test_corpus_input(rel):
    path = CORPUS / rel
    kind = path.parent.name
    out = classify(kind, lambda: _reader(kind)(path), path.name, invalid=not path.name.startswith("ok-"))
    assert out.status == ("ok" if path.name.startswith("ok-") else "clean"), f"{out.status}: {out.detail}"
