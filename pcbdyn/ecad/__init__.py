"""Boards from ECAD files: a KiCad layout (kiutils) with a small map of footprint names to part
families becomes a board.toml in pcbdyn's grammar. Reads layouts only; knows boards only as the
TOML text it writes (the command loads it back with ``pcbdyn.board.load_board``)."""

from .importer import Imported, import_kicad
from .kicad import KicadError

__all__ = ["Imported", "KicadError", "import_kicad"]
