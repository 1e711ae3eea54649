"""The domain-model interface: what the bridge to updating and diagnosis (:mod:`pcbdyn.problems`) asks
of a structure described in a TOML file. :class:`pcbdyn.board.Board` implements it, and so does every
other structure (a ribbed box), so that update, localize, study, diagnose, library calibration and
wedge-lock fitting work on any of them with no second copy.

A structure has a ``name``, the ``path`` of its file, its ``parameters``
(:class:`pcbdyn.targets.ParameterSpec`: named, bounded, with units), ``mesh_size`` [m] and
``analysis`` (``modes``, ``f_max``), and:

- ``configuration_names()``: its perturbed test configurations (PBC), besides the base one (None);
- ``build(config=None, mesh_size=None, shared_mesh=False)``: the FE model of one configuration as a
  :class:`pcbdyn.fe.parametric.ParametricModel` whose ``parameters`` give dK/dp and dM/dp, read at
  measurement points through the shell shape functions (``shared_mesh``: every configuration on one
  mesh, node for node);
- ``check_points(xyz, source)``: a :class:`StructureError` naming the measurement points (of
  ``source``, a file) that lie off the structure;
- ``write_updated(values, dst, source)``: its file with parameter ``values`` {name: SI} written into
  their targets, the user's comments and layout kept; returns the path written;
- ``write_enriched(effects, dst)``: its file with the effects a diagnosis found declared in it (the
  user's comments and layout kept); returns the path written;
- ``outlines(config=None)``: what a mode-shape picture outlines (plain data: kind, label, points).

A built model (:class:`pcbdyn.fe.parametric.ParametricModel`) adds what a diagnosis asks of it:
``layout_hints()`` (prime suspects, footprints, plate thickness) and ``with_shear_factor(f)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol


@dataclass
class Analysis:
    """A structure's ``[analysis]``: how many modes to solve, up to which frequency f_max [Hz]."""

    modes: int = 12
    f_max: float | None = None


class StructureError(ValueError):
    """A structure description, or data about it, that cannot be used: the message names the file,
    the field and the fix."""


class Structure(Protocol):
    """See the module docstring."""

    name: str
    parameters: list

    def configuration_names(self) -> list: ...

    def build(self, config=None, mesh_size=None, shared_mesh: bool = False): ...

    def check_points(self, xyz, source) -> None: ...

    def write_updated(self, values: dict, dst, source: str = "pcbdyn update"): ...

    def write_enriched(self, effects, dst): ...

    def outlines(self, config=None) -> list: ...
