"""Reading any structure's file: the top-level table decides its kind (``[board]``: a board, ``[box]``: a
ribbed shell housing)."""

from __future__ import annotations

from pathlib import Path

from ..board import BoardError, load_board
from ..box import load_box
from ..domain import StructureError
from ..inputs import read_toml

#: top-level table -> loader of that kind of structure
LOADERS = {"board": load_board, "box": load_box}


def load_structure(path):
    """The structure (domain-model interface, :mod:`pcbdyn.domain`) described by the TOML file ``path``."""
    _, data = read_toml(path, BoardError)
    kinds = [k for k in LOADERS if k in data]
    if len(kinds) != 1:
        raise StructureError(f"{Path(path).name}: the file must have exactly one of the tables "
                             f"{', '.join(f'[{k}]' for k in LOADERS)} (it tells what the file describes)")
    return LOADERS[kinds[0]](path)
