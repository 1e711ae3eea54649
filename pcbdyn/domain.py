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
- ``write_enriched(effects, dst, values=None)``: its file with the effects a diagnosis found declared
  in it and the fitted parameter ``values`` {name: SI} written into their targets (the user's comments
  and layout kept): the diagnosed model; returns the path written;
- ``outlines(config=None)``: what a mode-shape picture outlines (plain data: kind, label, points);
- ``following(lines)``: a copy whose meshes' element edges also follow ``lines`` (polylines on its
  plates, (m, 2) [m] on a board in its plane, (m, 3) in space on a housing), where a diagnosis found
  ribs; a :class:`StructureError` where it cannot be meshed along them.

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


#: most modes a structure's [analysis] (or a command's --modes) asks for
MAX_MODES = 200


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

    def write_enriched(self, effects, dst, values=None): ...

    def outlines(self, config=None) -> list: ...

    def following(self, lines): ...


#: fewest elements across a structure's smallest plate a mesh must have
MIN_ELEMENTS_ACROSS = 4
#: most DOFs a structure's mesh may have (estimated before meshing); the PCBDYN_MAX_DOFS variable raises it
MAX_DOFS = 1_200_000


def check_mesh_size(where: str, span: float, area: float, size: float, error, what: str = "the board's") -> None:
    """``error`` (a StructureError), with the estimate, for a mesh ``size`` [m] that gives fewer than
    :data:`MIN_ELEMENTS_ACROSS` elements across ``span`` [m] (``what``: whose span, for the message) or more
    DOFs than the limit (6 per node, about one node per element of size^2 on ``area`` [m^2]): before gmsh
    spends minutes on it. ``where``: the file and field, e.g. "board.toml: board.mesh_size"."""
    import os

    across = span / size
    if across < MIN_ELEMENTS_ACROSS:
        raise error(f"{where}: {size * 1e3:g} mm gives {across:.1f} elements across {what} "
                    f"{span * 1e3:g} mm; use at most {span / MIN_ELEMENTS_ACROSS * 1e3:g} mm")
    limit = int(float(os.environ.get("PCBDYN_MAX_DOFS", MAX_DOFS)))
    dofs = 6.0 * area / size**2
    if dofs > limit:
        raise error(f"{where}: {size * 1e3:g} mm gives about {dofs:,.0f} DOFs, more than the limit of "
                    f"{limit:,}; use a larger mesh size (about {(6.0 * area / limit) ** 0.5 * 1e3:.2g} "
                    "mm or more), or raise the limit with the PCBDYN_MAX_DOFS variable")


class Configured:
    """The test configurations of a structure (a dataclass with ``configurations``: entries with a
    ``name``), looked up by name: what board and box share."""

    def configuration(self, name):
        return next((c for c in self.configurations if c.name == name), None)

    def configuration_names(self) -> list:
        return [c.name for c in self.configurations]


def configuration_of(structure, name, error):
    """The ``[[configurations]]`` entry ``name`` of ``structure`` (None for None, the base one), or
    ``error`` naming the configurations there are."""
    if name is None:
        return None
    cfg = structure.configuration(name)
    if cfg is None:
        names = ", ".join(structure.configuration_names()) or "none defined"
        raise error(f"{structure.path.name}: configuration '{name}' does not exist (configurations: {names})")
    return cfg
