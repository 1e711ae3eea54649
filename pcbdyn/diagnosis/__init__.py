"""Diagnosis: find the effects a model lacks (issue 7). :mod:`.catalogue` is the registry of
candidate effects (one plugin module per kind), :mod:`.layout` says where they can go,
:mod:`.select` picks the effects that explain frequency residuals, :mod:`.model_form` bounds what
the mesh and the plate theory leave between model and test, :mod:`.pipeline` runs the whole
diagnosis."""

from .catalogue import (
    KINDS,
    Candidate,
    CatalogueError,
    add_effect,
    derivatives,
    eigenvalue_columns,
    frequency_columns,
    generate,
    kind,
    place,
)
from .layout import Layout, from_board, from_model
from .select import Selection, forward_select

__all__ = ["KINDS", "Candidate", "CatalogueError", "Layout", "Selection", "add_effect", "derivatives", "place",
           "eigenvalue_columns", "forward_select", "frequency_columns", "from_board", "from_model", "generate", "kind"]
