"""The bridge from structures (boards, boxes) and their measured data to the plain-matrix updating driver:
update, localisation, studies, library calibration and wedge-lock fitting build their equations here
(update, calibrate and wedgelock fit through :func:`pcbdyn.problems.fit.fit`), and diagnosis takes its
models from here."""

from .load import load_structure
from .models import StructureModels
from .problem import UpdateProblem
from .run import correlation_state, run
from .system import ConfigSystem, DynamicReduced, ShapePairing

__all__ = ["ConfigSystem", "DynamicReduced", "StructureModels", "UpdateProblem", "correlation_state",
           "load_structure", "run", "ShapePairing"]
