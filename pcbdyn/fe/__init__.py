"""A small, general finite element engine for structural dynamics (shells, beams, springs, masses).

It knows nothing of boards or parts: upper layers build a :class:`Model` and ask for
matrices, modes and FRFs.
"""

from .mesh import DOF_NAMES, NDOF, dof_index
from .properties import (
    BeamProperty,
    EdgeSpringProperty,
    EmbeddedBeamProperty,
    MassProperty,
    OrthotropicShellProperty,
    ShellProperty,
    SpringProperty,
)
from .model import ElementSet, Model, ModelError

__all__ = [
    "DOF_NAMES",
    "NDOF",
    "dof_index",
    "BeamProperty",
    "EdgeSpringProperty",
    "EmbeddedBeamProperty",
    "MassProperty",
    "OrthotropicShellProperty",
    "ShellProperty",
    "SpringProperty",
    "ElementSet",
    "Model",
    "ModelError",
]
