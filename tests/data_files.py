"""Input files shared by the tests (tests/data): boards that several tests build, read as they are or
with a few fields changed, so that no test retypes a board."""

import os
from pathlib import Path

DATA = Path(__file__).resolve().parent / "data"


def board_file(name: str) -> Path:
    """The path of a shared board file (tests/data/boards/<name>)."""
    return DATA / "boards" / name


def board_text(name: str, extra: str = "", **changes) -> str:
    """The text of a shared board with ``old=new`` replacements (``changes`` maps a label to an
    (old, new) pair of exact substrings, each of which must be present) and ``extra`` appended."""
    text = board_file(name).read_text()
    for label, (old, new) in changes.items():
        if old not in text:
            raise KeyError(f"{name}: '{old}' ({label}) is not in the file")
        text = text.replace(old, new)
    return text + extra


def write_board(tmp_path, text: str, name: str = "board.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


#: third-party files from outside the project (../shared/realdata beside the clone; PCBDYN_REALDATA names
#: another place, e.g. for a worktree): never committed, tests that read them skip where it is absent
REALDATA = Path(os.environ.get("PCBDYN_REALDATA", Path(__file__).resolve().parents[1] / ".." / "shared" / "realdata"))


def realdata(folder: str):
    """(path of ``folder`` of the third-party files, a pytest skip mark for where it is absent)."""
    import pytest

    path = REALDATA / folder
    return path, pytest.mark.skipif(not path.is_dir(), reason=f"the third-party test files ({path}: {folder}'s data, "
                                                               "not part of the project) are not beside this clone")
