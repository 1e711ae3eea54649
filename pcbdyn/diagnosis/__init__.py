"""Diagnosis: find the effects a model lacks (issue 7). :mod:`.catalogue` is the registry of
candidate effects (one plugin module per kind), :mod:`.layout` says where they can go,
:mod:`.select` picks the effects that explain frequency residuals, :mod:`.model_form` bounds what
the mesh and the plate theory leave between model and test, :mod:`.pipeline` runs the whole
diagnosis."""

# the kinds of effects, registered in the order candidates are generated and searched
from . import point_mass  # noqa: F401  (point_mass, point_inertia)
from . import ground_spring  # noqa: F401
from . import edge_stiffness  # noqa: F401
from . import region_stiffness  # noqa: F401
from . import stiffener  # noqa: F401
from . import line_mass  # noqa: F401
from . import region_mass  # noqa: F401
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
from .layout import Layout, from_model, from_structure
from .select import forward_select
from .selection import Selection

__all__ = ["KINDS", "Candidate", "CatalogueError", "Layout", "Selection", "add_effect", "derivatives", "place",
           "eigenvalue_columns", "forward_select", "frequency_columns", "from_model", "from_structure", "generate", "kind"]
