"""Model exchange with other FE codes. Works on :class:`pcbdyn.fe.Model` only (no boards, no
parts), so every domain model that builds an fe.Model (board.toml, box.toml) exports alike."""

from .nastran import Deck, nastran_deck, write_nastran

__all__ = ["Deck", "nastran_deck", "write_nastran"]
