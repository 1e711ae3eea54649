"""Boards as domain objects: board.toml -> validated description -> mesh -> FE model with parameters."""

from .board import Board, load_board, parse_board
from .entries import BoardError
from .model import BoardModel, build_model

__all__ = ["Board", "BoardError", "BoardModel", "build_model", "load_board", "parse_board"]
