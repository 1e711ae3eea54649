"""What the reference tests of the input formats share: the fields a reader accepts in one table (asked
from the reader itself, through its message for an unknown field) and the names a reference writes as code."""

import copy
import re
from pathlib import Path

import pytest


def allowed_fields(parse, error, data: dict, path, file: str) -> list:
    """The fields ``parse(data, Path(file))`` accepts in the table of ``data`` at ``path`` (keys; an int: an
    entry of an array): its ``error`` for an unknown field lists them."""
    data = copy.deepcopy(data)
    table = data
    for key in path:
        table = table[key]
    table["qqqqzzzz"] = 1
    with pytest.raises(error) as err:
        parse(data, Path(file))
    message = str(err.value)
    assert "unknown field; allowed: " in message, message
    return message.split("allowed: ")[1].split(", ")


def documented(reference: Path) -> set:
    """The names ``reference`` writes as code (outside its examples); `[board]` also counts as `board`."""
    text = re.sub(r"```.*?```", "", reference.read_text(), flags=re.S)
    return {name for code in re.findall(r"`([^`\n]+)`", text) for name in (code, code.strip("[]"))}
