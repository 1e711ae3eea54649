"""docs/box-toml.md is whole: every field the box.toml reader accepts (asked from the reader itself, through
its message for an unknown field) and every target of a box is in it, and its TOML examples are valid."""

import re
import tomllib
from pathlib import Path

import pytest

from pcbdyn.box import BoxError, parse_box

import reference_checks

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "docs" / "box-toml.md"


def every_table() -> dict:
    data = tomllib.loads((ROOT / "examples" / "ribbed_box" / "box.toml").read_text())
    data["joints"] = [{"name": "j", "plates": ["upper", "left"], "k_rot": "1e5 N*m/rad/m"}]
    data["configurations"] = [{"name": "c2", "masses": [{"plate": "upper", "at": ["10 mm", "10 mm"], "mass": "5 g"}]}]
    data["analysis"]["f_max"] = "2000 Hz"
    return data


TABLES = [(), ("box",), ("materials", "al"), ("plates", 0), ("ribs", 0), ("supports", 0), ("joints", 0), ("masses", 0),
          ("configurations", 0), ("configurations", 0, "masses", 0), ("parameters", 0), ("analysis",)]


def documented() -> set:
    return reference_checks.documented(REFERENCE)


def test_the_box_with_every_table_is_valid():
    box = parse_box(every_table(), Path("box.toml"))
    assert box.joints and box.configurations and box.masses and box.supports and box.ribs


@pytest.mark.parametrize("path", TABLES, ids=lambda p: ".".join(map(str, p)) or "top")
def test_every_field_the_box_reader_accepts_is_documented(path):
    fields = reference_checks.allowed_fields(parse_box, BoxError, every_table(), path, "box.toml")
    assert not [f for f in fields if f not in documented()]


def test_every_box_target_and_choice_is_documented():
    data = every_table()
    data["parameters"][0]["target"] = "nothing.here"
    with pytest.raises(BoxError) as err:
        parse_box(data, Path("box.toml"))
    forms = set(re.findall(r"[a-z_]+\.<\w+>\.[A-Za-z_]+", str(err.value).split("targets are ")[1]))
    assert len(forms) == 8 and not forms - documented()
    assert {"u0", "u1", "v0", "v1", '"+n"', '"-n"', '"clamped"', '"hinged"', '"beam"', '"shell"'} <= documented()


def test_every_toml_example_of_the_box_reference_is_valid_toml():
    blocks = re.findall(r"```toml\n(.*?)```", REFERENCE.read_text(), re.S)
    assert len(blocks) >= 9
    for block in blocks:
        tomllib.loads(block)
