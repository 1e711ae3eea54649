"""Boards as domain objects: board.toml -> validated description -> mesh -> FE model with parameters."""

from .model import BoardModel, build_model
from .parameters import Parameter
from .spec import Board, BoardError, load_board

__all__ = ["Board", "BoardError", "BoardModel", "Parameter", "build_model", "load_board"]
