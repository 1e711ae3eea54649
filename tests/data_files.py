"""Input files shared by the tests (tests/data): boards that several tests build, read as they are or
with a few fields changed, so that no test retypes a board."""

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
