"""One test configuration of one structure as the plain-matrix updating driver sees it: the matrices and
their parameter derivatives on the independent DOFs, the model read at the measurement points, the
excited DOF of an FRF, and how measured modes pair with the model's."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..correlation.pairing import FREQ_LIMIT, pair_modes
from ..domain import StructureError
from ..fe.constraints import build_reduction
from ..fe.parametric_matrices import ParametricMatrices
from ..fe.probe import model_probe
from ..updating.matching import dynamic_basis
from .models import parameter_values


class ProblemError(StructureError):
    """An updating problem that its structures and tests cannot make (no parameters, an unknown one, a
    method that needs shapes the test lacks, ...); the message names the file or option and the fix."""


class ConfigSystem:
    """``model(p)`` returns (K, M, dKs, dMs) reduced to the independent DOFs (CSC), one derivative pair per
    parameter of ``names`` (zero for those the built model ``pm`` lacks), from the model's
    :class:`pcbdyn.fe.parametric_matrices.ParametricMatrices`, as the diagnosis residual takes them
    (:class:`pcbdyn.problems.StructureModels`): no element matrix is recomputed as ``p`` moves. The last
    evaluation is cached (the driver and its line search ask for the same p more than once)."""

    def __init__(self, pm, names, label: str = "base"):
        self.pm, self.names, self.label = pm, list(names), label
        self.parametric = ParametricMatrices(pm, self.names)
        K, M = self.parametric.matrices([pm.parameters[n].value if n in pm.parameters else 0.0 for n in self.names])
        self.reduction = build_reduction(pm.model, K, M)
        self.n_rigid = 6 if pm.model.free else 0
        self._cache = (None, None)
        self._restricted = (None, None)

    def model(self, p):
        """(K, M, dKs, dMs) at parameter values ``p`` [SI], on the independent DOFs."""
        p = np.asarray(p, float)
        if self._cache[0] is not None and np.array_equal(self._cache[0], p):
            return self._cache[1]
        red = self.reduction.reduce
        K, M = self.parametric.matrices(p)
        pairs = self.parametric.derivatives(p)
        out = (red(K), red(M), [red(dK) for dK, _ in pairs], [red(dM) for _, dM in pairs])
        self._cache = (p.copy(), out)
        return out

    def restricted(self, p, dofs) -> list:
        """[(rows, A[rows][:, dofs])] of K, M, the dKs and the dMs at ``p`` on ``dofs``, ``rows`` their
        non-zero rows within ``dofs``: what every measured mode's dynamic reduction of this configuration
        at ``p`` multiplies (made once per p, not once per mode)."""
        key = (np.asarray(p, float).tobytes(), dofs.tobytes())
        if self._restricted[0] != key:
            K, M, dKs, dMs = self.model(p)
            pieces = []
            for A in (K, M, *dKs, *dMs):
                A = sp.csr_matrix(A)[dofs][:, dofs]
                rows = np.unique(A.nonzero()[0])
                pieces.append((rows, A[rows]))
            self._restricted = (key, pieces)
        return self._restricted[1]

    def at(self, p):
        """The built model (:class:`pcbdyn.fe.parametric.ParametricModel`) at parameter values ``p``."""
        return self.pm.with_parameters(parameter_values(self.pm, self.names, p))

    def measurement_matrix(self, xyz, directions) -> sp.csr_matrix:
        """P (n_meas, n_independent): the model read at the points along the directions."""
        P = model_probe(self.pm.model, xyz, directions).P
        return sp.csr_matrix(P @ self.reduction.T)

    def excitation_dof(self, xyz, direction):
        """(independent DOF index, note or None) of a unit force at point ``xyz`` along ``direction``.
        The FRF equations (3.34, 3.35, 3.40) take one excited DOF: a point on a node along an axis maps
        to it exactly; otherwise the DOF with the largest interpolation weight is used and the note
        says so (move the excitation onto a node, e.g. with a mesh size that divides its coordinates)."""
        row = self.measurement_matrix(np.asarray(xyz, float)[None], np.asarray(direction, float)[None]).toarray()[0]
        w = np.abs(row)
        where = np.round(np.asarray(xyz) * 1e3, 2).tolist()
        if w.max() == 0:
            raise ProblemError(f"excitation at {where} mm moves no free DOF")
        j = int(np.argmax(w))
        if np.isclose(row[j], 1.0) and np.sum(w > 1e-9) == 1:
            return j, None
        return j, (f"excitation at {where} mm is not on a node along an axis: the nearest-weight DOF is excited "
                   "instead (biased); put the excitation on a mesh node")

    def pairing(self, measured, min_mac: float = 0.5, limit: float = FREQ_LIMIT):
        """The driver's pairing callable for the measured modes ``measured`` (:class:`pcbdyn.testdata.MeasuredModes`):
        by MAC (:func:`pcbdyn.correlation.pairing.pair_modes`) when shapes are measured, pairs more than
        ``limit`` apart in frequency left out, else by the test's mode numbers; rigid-body modes never pair."""
        return ShapePairing(min_mac, self.n_rigid, None if measured.shapes is not None else measured.numbers, limit)


class ShapePairing:
    """A pairing callable (f_a, phi_a, f_x, phi_x) -> analytical index per measured mode (-1: unpaired):
    by MAC, each model mode used once (:func:`pcbdyn.correlation.pairing.pair_modes`), past the first
    ``n_rigid`` (rigid-body) analytical modes, a pair beyond the frequency ``limit`` (relative; default
    :data:`pcbdyn.correlation.pairing.FREQ_LIMIT`) left out; with ``numbers`` (1-based elastic mode numbers,
    for frequencies without shapes) by those numbers. ``last``: the
    :class:`~pcbdyn.correlation.pairing.Pairing` of the last call, for its warnings."""

    def __init__(self, min_mac: float, n_rigid: int = 0, numbers=None, limit: float = FREQ_LIMIT):
        self.min_mac, self.n_rigid, self.numbers, self.limit = min_mac, n_rigid, numbers, limit
        self.last = None

    def __call__(self, f_a, phi_a, f_x, phi_x):
        out = -np.ones(np.size(f_x), int)
        n_rigid, numbers = self.n_rigid, self.numbers
        if numbers is not None or phi_x is None:
            k = n_rigid + (np.arange(np.size(f_x)) + 1 if numbers is None else np.asarray(numbers)) - 1
            ok = k < np.size(f_a)
            out[ok] = k[ok]
            return out
        self.last = pair_modes(np.asarray(phi_x), np.asarray(phi_a)[:, n_rigid:], f_x, np.asarray(f_a)[n_rigid:],
                               min_mac=self.min_mac, limit=self.limit)
        for pr in self.last.pairs:
            if pr.used:
                out[pr.test] = pr.model + n_rigid
        return out

    def warnings(self) -> list:
        """The last pairing's warnings (aliased model modes, pairs beyond the frequency limit), with elastic
        mode numbers (no model frequencies: an update's before and after say the same)."""
        return [] if self.last is None else self.last.warnings()


class DynamicReduced:
    """``model(p)`` of one measured mode: the structure reduced onto the measured DOFs by the dynamic map
    at that mode's measured angular frequency ``omega`` (thesis ch. 2.2; P T = I, T frozen within an
    evaluation, so T^T dK T is the exact derivative of the condensed dynamic stiffness). At the test
    frequency the condensation is exact for the mode there, unlike Guyan's static one, so shape
    equations on it carry no reduction bias."""

    def __init__(self, system: ConfigSystem, P, omega: float):
        self.system, self.P, self.omega = system, P, float(omega)

    def __call__(self, p):
        K, M, dKs, dMs = self.system.model(p)
        dofs, T = dynamic_basis(K, M, self.P, self.omega)
        pieces = self.system.restricted(p, dofs)

        def red(piece):
            rows, A = piece  # the rows of the DOFs a matrix touches: a parameter's derivative, a few elements
            return np.asarray(T[rows].T @ (A @ T))

        Kr, Mr = red(pieces[0]), red(pieces[1])
        n = len(dKs)
        return (0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T), [red(x) for x in pieces[2:2 + n]],
                [red(x) for x in pieces[2 + n:]])
