"""A structure's test configurations as FE models that are functions of its declared parameters: the
matrices and parameter derivatives the updating driver and the diagnosis residual both start from."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def parameter_values(pm, names, p) -> dict:
    """{name: value} of the parameters ``names`` that the built model ``pm`` has (a structure of a
    multi-structure problem carries only its own)."""
    return {n: float(v) for n, v in zip(names, np.asarray(p, float).tolist()) if n in pm.parameters}


def parameter_derivatives(pm, names) -> list:
    """[(dK/dp, dM/dp)] (full size, before constraints) of each parameter of ``names`` at ``pm``'s
    values; zero for a parameter ``pm`` does not have. Central differences of the sets each touches:
    for a one-off derivative (a library's frequency scatter); fits, which move ``p``, take theirs
    from :class:`pcbdyn.fe.parametric_matrices.ParametricMatrices`."""
    n = pm.model.n_dof
    zero = sp.csr_matrix((n, n))
    return [pm.parameters[name].derivatives(pm) if name in pm.parameters else (zero, zero) for name in names]


class StructureModels:
    """The models of ``configs`` (configuration names, None for the base one) of ``structure`` (the
    domain-model interface, :mod:`pcbdyn.domain`) as functions of its parameters ``names`` (default: all
    of them). ``shared_mesh``: all configurations on one mesh, node for node. Attributes: ``models``
    (the built :class:`pcbdyn.fe.parametric.ParametricModel` of each configuration), ``p0`` and
    ``bounds`` [SI] of the parameters. Matrices and derivatives at other values come from each
    configuration's :class:`pcbdyn.fe.parametric_matrices.ParametricMatrices` (made when first asked
    for): no element matrix is recomputed as the parameters move."""

    def __init__(self, structure, configs, names=None, mesh_size=None, shared_mesh: bool = False):
        self.structure = structure
        self.configs = list(configs)
        self.names = [p.name for p in structure.parameters] if names is None else list(names)
        self.models = [structure.build(c, mesh_size, shared_mesh) for c in self.configs]
        params = [self.models[0].parameters[n] for n in self.names]
        self.p0 = np.array([p.value for p in params], float)
        self.bounds = (np.array([p.bounds[0] for p in params], float), np.array([p.bounds[1] for p in params], float))
        self._matrices = None

    @property
    def parametric(self) -> list:
        """The :class:`pcbdyn.fe.parametric_matrices.ParametricMatrices` of each configuration."""
        if self._matrices is None:
            from ..fe.parametric_matrices import ParametricMatrices

            self._matrices = [ParametricMatrices(pm, self.names) for pm in self.models]
        return self._matrices

    def at(self, p) -> list:
        """The models with the parameters at ``p`` [SI]."""
        return [pm.with_parameters(parameter_values(pm, self.names, p)) for pm in self.models]

    def build(self, p) -> list:
        """The FE models (fe.Model) at ``p``."""
        return [pm.model for pm in self.at(p)]

    def matrices(self, p) -> list:
        """Per configuration, (K, M) at ``p`` [SI] (full size, before constraints; the index arrays
        of one configuration's matrices are the same at every ``p``)."""
        return [pmx.matrices(p) for pmx in self.parametric]

    def derivatives(self, p, models=None) -> list:
        """Per configuration, [(dK, dM)] of every parameter at ``p`` (``models``: unused, the
        signature of a residual's ``derivatives(p, models)``)."""
        return [pmx.derivatives(p) for pmx in self.parametric]
