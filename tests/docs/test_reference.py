"""The documentation is whole and stays inside the repository: every field board.toml accepts is
in docs/board-toml.md (the fields are asked from the reader itself, through its message for an
unknown field), and README, docs and examples refer only to files that exist in the repository."""

import copy
import re
import tomllib
from pathlib import Path

import pytest

from pcbdyn.board import BoardError
from pcbdyn.board.laminate import MATERIALS
from pcbdyn.board import parse_board
from pcbdyn.board.entries import FIXTURE_TYPES
from pcbdyn.components.library import MODELS

import reference_checks

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "docs" / "board-toml.md"

EVERY_TABLE = tomllib.loads((Path(__file__).parent / "every_table.toml").read_text())

#: every table of board.toml, as the path of keys (an int: an entry of an array) to it
TABLES = [(), ("board",), ("board", "outline"), ("board", "outline", "holes", 0), ("board", "stackup", 0),
          ("components", 0), ("fixtures", 0), ("masses", 0), ("line_masses", 0), ("stiffeners", 0),
          ("stiffeners", 0, "section"), ("regions", 0), ("configurations", 0), ("configurations", 0, "masses", 0),
          ("parameters", 0), ("analysis",)]


def allowed_fields(path) -> list:
    return reference_checks.allowed_fields(parse_board, BoardError, EVERY_TABLE, path, "board.toml")


def documented() -> set:
    return reference_checks.documented(REFERENCE)


def test_the_example_with_every_table_is_a_valid_board():
    board = parse_board(copy.deepcopy(EVERY_TABLE), Path("board.toml"))
    assert board.stiffeners and board.regions and board.line_masses and board.configurations


@pytest.mark.parametrize("path", TABLES, ids=lambda p: ".".join(map(str, p)) or "top")
def test_every_field_the_reader_accepts_is_documented(path):
    missing = [f for f in allowed_fields(path) if f not in documented()]
    assert not missing, f"fields of {path or 'the top level'} not in docs/board-toml.md: {missing}"


def test_every_fixture_type_part_model_material_and_target_is_documented():
    names = documented()
    assert not [t for t in FIXTURE_TYPES if t not in names]
    assert not [m for m in MODELS if m not in names]
    assert not [m for m in MATERIALS if m not in names]
    data = copy.deepcopy(EVERY_TABLE)
    data["parameters"][0]["target"] = "nothing.here"
    with pytest.raises(BoardError) as err:
        parse_board(data, Path("board.toml"))
    forms = set(re.findall(r"[a-z_]+\.(?:<\w+>\.)?[A-Za-z_]+", str(err.value).split("targets are ")[1]))
    assert len(forms) > 10
    assert not [t for t in forms if t not in names]


def test_every_toml_example_of_the_reference_is_valid_toml():
    blocks = re.findall(r"```toml\n(.*?)```", REFERENCE.read_text(), re.S)
    assert len(blocks) >= 12
    for block in blocks:
        tomllib.loads(block)


def repo_paths(text: str, base: Path) -> list:
    """Files a text refers to: relative markdown links, and `paths` under the repository's folders."""
    links = [m for m in re.findall(r"\]\(([^)#\s]+)", text) if not re.match(r"[a-z]+:", m)]
    ticks = re.findall(r"`((?:\.\./|examples/|pcbdyn/|tests/|docs/|benchmarks/|scripts/)[^`\s]*)`", text)
    return [(base / p) if p.startswith(("../", "./")) or p in links else ROOT / p for p in links + ticks]


def test_readme_docs_and_examples_refer_only_to_files_in_the_repository():
    texts = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    examples = [p for p in sorted((ROOT / "examples").rglob("*")) if p.suffix in (".toml", ".csv", ".md")]
    bad = []
    for f in texts:
        for target in repo_paths(f.read_text(), f.parent):
            if not target.resolve().is_relative_to(ROOT) or not target.exists():
                bad.append(f"{f.relative_to(ROOT)} -> {target}")
    for f in examples:
        text = f.read_text()
        bad += [f"{f.relative_to(ROOT)} mentions shared/" for _ in re.findall(r"shared/", text)]
        for name in re.findall(r'"([^"\s]+\.(?:toml|csv|uff|md))"', text):
            target = (f.parent / name).resolve()
            if not target.is_relative_to(ROOT) or not target.exists():
                bad.append(f"{f.relative_to(ROOT)} -> {name}")
    assert not bad
