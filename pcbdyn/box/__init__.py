"""Boxes as domain objects: box.toml -> validated description of plates, ribs, joints, supports and
masses in 3-D -> one conforming shell mesh -> FE model with parameters, behind the same domain-model
interface (:mod:`pcbdyn.domain`) as boards."""

from .box import Box, load_box, parse_box
from .entries import BoxError
from .model import BoxModel, build_model

__all__ = ["Box", "BoxError", "BoxModel", "build_model", "load_box", "parse_box"]
