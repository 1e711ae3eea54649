"""Cases of success-ratio studies of error localisation (thesis sections 5.3-5.4, 6.4.2): what
:func:`pcbdyn.updating.study.run_study` asks of a case (:class:`~pcbdyn.updating.study.StudyCase`) on
the thesis' simulated free PCB and on any structure's file."""

from __future__ import annotations

from dataclasses import replace
from typing import ClassVar

import numpy as np

from ..correlation.mac import paired_mac
from ..domain import MAX_MODES, StructureError
from ..fe.assembly import element_matrices, scatter
from ..fe.generate import rectangle
from ..fe.model import Model
from ..fe.properties import ShellProperty
from ..fe.reduction import guyan
from ..testdata import read_points_csv
from ..testdata.noise import add_noise
from ..updating import matching
from ..updating.equations import fbm_equations, frequency_equations, frf_receptance_equations, qms_equations
from ..updating.pbc import stack
from ..updating.sensitivity import frequencies_hz, pencil_modes
from ..updating.study import StudyCase, unit_weighted
from ..updating.weighting import unit_row_weights
from .problem import UpdateProblem

class CaseError(StructureError):
    """Options of a study case that cannot be used (an element or node that does not exist, a truth
    equal to the model); the message names the option and the fix."""


#: the thesis' simulated free PCB (section 5.4.4, Table 5.10): 162 x 178 x 2.8 mm, E 26 GPa,
#: rho 2640 kg/m^3 on a 6 x 7 mesh; element thicknesses [mm] of the model ("pa") and of the
#: structure that produced the simulated test ("px"), by thesis element number
SIMULATED_PCB = {
    "Lx_m": 0.162, "Ly_m": 0.178, "t_base_m": 2.8e-3, "E": 26e9, "rho": 2640.0,
    "thickness_mm": {
        "pa": {"9": 3.2, "27": 3.2, "11": 3.0, "13": 3.0, "23": 3.0, "25": 3.0},
        "px": {"9": 3.2, "11": 3.2, "13": 3.2, "23": 3.2, "25": 3.2, "27": 3.2},
    },
}
class SimulatedFreePCB(StudyCase):
    """The thesis' simulated free PCB (section 5.4.4, Tables 5.10-5.11, Fig. 5.41).

    162 x 178 x 2.8 mm glass-epoxy plate (E 26 GPa, rho 2640, nu 0.35), 6 x 7 quad4 shells, one
    element set and one thickness parameter per element (thesis numbering e = 7 ix + iy + 1,
    nodes n = 8 ix + iy + 1), free-free. Only the bending DOFs (w, rx, ry) take part (a flat
    plate's membrane is uncoupled); like the thesis' reduced ANSYS solution both the model (p_a)
    and the simulated test (p_x) are Guyan-condensed onto the 56 w DOFs, the measured points.
    Sensitivities dK/dt_e, dM/dt_e come from central differences of the element matrices,
    condensed with the model's Guyan transformation.

    ``errors_mm``: {element number: true thickness [mm]} replacing the table's p_x (to pose
    another problem); the model keeps Table 5.10's p_a. Equation types (``equations``):
    ``qms``/``fbm`` with the first ``n_modes`` elastic modes; ``frf``: indirect receptance
    residuals (eq. 3.35) for a force at node ``excitation_node`` at two updating frequencies per
    mode, 3 % below the lower and 3 % above the higher of the paired resonances (as the thesis'
    Table 5.12 brackets them); ``frf+pbc``: those stacked with the same equations of the
    configuration with ``perturbation_kg`` added at node ``perturbation_node`` (thesis 6.4.2,
    Fig. 6.3), each configuration row-weighted on its own.
    """

    kinds = ("qms", "fbm", "frf", "frf+pbc")
    #: the options a study file may set (:func:`.study_spec.read_spec` checks them): (kind, lower, upper)
    #: of a number, "names" (a list of names) or "elements" (element number -> thickness [mm]); the node
    #: options are thesis node numbers (n = 8 ix + iy + 1, Fig. 5.41)
    options: ClassVar[dict] = {
        "nu": (float, -0.99, 0.499), "n_modes": (int, 1, 50), "errors_mm": "elements", "excitation_node": (int, 1, 56),
        "perturbation_node": (int, 1, 56), "perturbation_kg": (float, 1e-6, 1e3)}

    def __init__(self, nu: float = 0.35, n_modes: int = 7, errors_mm: dict | None = None,
                 excitation_node: int = 43, perturbation_node: int = 56, perturbation_kg: float = 0.01,
                 freq_margin: float = 0.03):
        c = SIMULATED_PCB
        nx, ny = 6, 7
        nodes, conn = rectangle(c["Lx_m"], c["Ly_m"], nx, ny)
        thesis_cell = np.array([j * nx + i for i in range(nx) for j in range(ny)])
        self.conn = conn[thesis_cell]
        self.nodes = nodes
        #: our node index of thesis node n (1-based) is node_of[n - 1]
        self.node_of = np.array([j * (nx + 1) + i for i in range(nx + 1) for j in range(ny + 1)])
        self.n_modes = int(n_modes)
        n_el = len(self.conn)
        self.parameter_names = [f"t{e + 1}" for e in range(n_el)]
        self.p_a = np.full(n_el, c["t_base_m"])
        for k, v in c["thickness_mm"]["pa"].items():
            self.p_a[int(k) - 1] = v * 1e-3
        self.p_x = self.p_a.copy()
        errors = c["thickness_mm"]["px"] if errors_mm is None else errors_mm
        for k, v in errors.items():
            if not 1 <= int(k) <= n_el:
                raise CaseError(f"errors_mm: element {k} does not exist; elements are 1..{n_el}")
            self.p_x[int(k) - 1] = float(v) * 1e-3
        self.true_errors = np.flatnonzero(np.abs(self.p_x / self.p_a - 1) > 1e-12)
        if self.true_errors.size == 0:
            raise CaseError("errors_mm: no element differs from the model (p_a): nothing to localise")

        model = Model(nodes)
        self._base = ShellProperty(E=c["E"], nu=nu, rho=c["rho"], t=c["t_base_m"])
        model.add("plate", "quad4", self.conn, self._base)
        n_dof = model.n_dof
        nn = nodes.shape[0]
        bend = np.sort(np.concatenate([6 * np.arange(nn) + 2, 6 * np.arange(nn) + 3, 6 * np.arange(nn) + 4]))
        masters = 3 * np.arange(nn)  # w in the bending-DOF ordering

        def element_set(t):
            K, M = zip(*(element_matrices(model, "plate", replace(self._base, t=float(tk))) for tk in np.unique(t)))
            idx = np.searchsorted(np.unique(t), t)
            cells = np.arange(n_el)
            return np.stack(K)[idx, cells], np.stack(M)[idx, cells]

        def system(t):
            Ke, Me = element_set(t)
            return scatter(n_dof, self.conn, Ke)[bend][:, bend], scatter(n_dof, self.conn, Me)[bend][:, bend]

        Ka, Ma = system(self.p_a)
        T, self.K, self.M = guyan(Ka, Ma, masters)
        _, Kx, Mx = guyan(*system(self.p_x), masters)
        h = 1e-6
        Kp, Mp = element_set(self.p_a * (1 + h))
        Km, Mm = element_set(self.p_a * (1 - h))
        step = (2 * h * self.p_a)[:, None, None]
        dKe, dMe = (Kp - Km) / step, (Mp - Mm) / step
        self.dKs, self.dMs = [], []
        for e in range(n_el):
            for de, out in ((dKe, self.dKs), (dMe, self.dMs)):
                d = scatter(n_dof, self.conn[e:e + 1], de[e:e + 1])[bend][:, bend]
                out.append(np.asarray(T.T @ (d @ T)))
        self.excitation = int(self.node_of[excitation_node - 1])
        dm = np.zeros(nn)
        dm[self.node_of[perturbation_node - 1]] = perturbation_kg
        self.configs = []
        for added in (np.zeros(nn), dm):
            Mc, Mxc = self.M + np.diag(added), Mx + np.diag(added)
            lam_a, _ = pencil_modes(self.K, Mc)
            lam_x, phi_x = pencil_modes(Kx, Mxc)
            el = slice(3, 3 + self.n_modes)  # 3 rigid-body modes (w, rx, ry)
            f_a, f_x = frequencies_hz(lam_a[el]), frequencies_hz(lam_x[el])
            f_u = np.sort(np.concatenate([(1 - freq_margin) * np.minimum(f_a, f_x),
                                          (1 + freq_margin) * np.maximum(f_a, f_x)]))
            w_u = 2 * np.pi * f_u
            H = np.column_stack([np.linalg.solve(Kx - w**2 * Mxc, np.eye(nn)[:, self.excitation]) for w in w_u])
            self.configs.append({"M": Mc, "omega_x": np.sqrt(lam_x[el]), "phi_x": phi_x[:, el],
                                 "f_a": f_a, "f_x": f_x, "omegas": w_u, "H_x": H})

    @property
    def n_params(self) -> int:
        return len(self.parameter_names)

    def measure(self, kind: str, level_pct: float, rng) -> tuple:
        """The simulated test data equations of type ``kind`` use, with ``level_pct`` % uniform
        noise (eqs. 5.72-5.74) drawn from ``rng``: (omega, shapes) or one FRF matrix per
        configuration."""
        if kind in ("qms", "fbm"):
            c = self.configs[0]
            return add_noise(c["omega_x"], level_pct, rng), add_noise(c["phi_x"], level_pct, rng)
        return tuple(add_noise(c["H_x"], level_pct, rng) for c in self.configs[: 1 if kind == "frf" else 2])

    def build(self, kind: str, data: tuple):
        """Weighted (A, b) of equation type ``kind`` from test data (:meth:`measure`)."""
        if kind in ("qms", "fbm"):
            build = qms_equations if kind == "qms" else fbm_equations
            return unit_weighted(build(self.K, self.configs[0]["M"], *data, self.dKs, self.dMs, self.p_a))
        return tuple(stack([unit_weighted(frf_receptance_equations(
            self.K, c["M"], c["omegas"], H, self.excitation, self.dKs, self.dMs, self.p_a))
            for c, H in zip(self.configs, data)]))


class StructureCase(StudyCase):
    """A success-ratio case from any structure (a loaded board.toml, box.toml): its ``[[parameters]]`` (or
    ``params``) at their values are the model, ``truth`` ({parameter name: SI value}, as
    :func:`.study_spec.read_spec` checks it) the simulated structure, measured at the points of
    ``points_csv`` (first ``n_modes`` elastic modes, paired in order; checked by MAC).

    Like the thesis' reduced models, the model and its derivatives are condensed once onto the
    measured DOFs (:func:`~.matching.reduce_system`), so each noisy shot only rebuilds small
    equations: ``qms``, ``fbm`` or ``freq`` (eigenvalue sensitivities of the full model; noise
    enters b only).
    """

    kinds = ("qms", "fbm", "freq")
    #: the options a study file may set (see :attr:`SimulatedFreePCB.options`)
    options: ClassVar[dict] = {"n_modes": (int, 1, MAX_MODES), "params": "names"}

    def __init__(self, structure, truth: dict, points_csv, n_modes: int = 6, params=None):
        problem = UpdateProblem(structure, params)
        self.parameter_names = list(problem.names)
        self.p_a = problem.p0.copy()
        self.p_x = self.p_a.copy()
        for name, value in truth.items():
            self.p_x[self.parameter_names.index(name)] = float(value)
        self.true_errors = np.flatnonzero(np.abs(self.p_x / self.p_a - 1) > 1e-12)
        if self.true_errors.size == 0:
            raise CaseError("truth: every value equals the board's: nothing to localise")
        points, dofs = read_points_csv(points_csv)
        sysm = problem.system(None)
        P = sysm.measurement_matrix(points.xyz[points.index(dofs.point_ids)], dofs.directions)
        nr, el = sysm.n_rigid, slice(sysm.n_rigid, sysm.n_rigid + int(n_modes))
        Kx, Mx, _, _ = sysm.model(self.p_x)
        lam_x, phi_full = pencil_modes(Kx, Mx, nr + int(n_modes))
        K, M, dKs, dMs = sysm.model(self.p_a)
        lam_a, Phi_a = pencil_modes(K, M, nr + int(n_modes))
        self.omega_x, self.phi_x = np.sqrt(lam_x[el]), np.asarray(P @ phi_full[:, el])
        paired = paired_mac(np.asarray(P @ Phi_a[:, el]), self.phi_x)
        if np.any(paired < 0.8):
            raise CaseError(f"truth: the true board's modes do not pair in order with the model's (MAC "
                             f"{np.round(paired, 2).tolist()}); use smaller errors or fewer modes (n_modes)")
        self.K, self.M, self.dKs, self.dMs = matching.reduce_system(K, M, dKs, dMs, P)
        blk = frequency_equations(lam_a[el], Phi_a[:, el], frequencies_hz(lam_x[el]), dKs, dMs, self.p_a)
        self._d = unit_row_weights(blk.A)
        self._A_freq = blk.A * self._d[:, None]
        self._f_a = frequencies_hz(lam_a[el])

    def measure(self, kind: str, level_pct: float, rng) -> tuple:
        """(omega,) or (omega, shapes) of the simulated test with ``level_pct`` % uniform noise
        (eqs. 5.72-5.73) drawn from ``rng``."""
        om = add_noise(self.omega_x, level_pct, rng)
        return (om,) if kind == "freq" else (om, add_noise(self.phi_x, level_pct, rng))

    def build(self, kind: str, data: tuple):
        """Weighted (A, b) of equation type ``kind`` from test data (:meth:`measure`); the
        frequency equations' A comes from the model alone (noise enters b only)."""
        if kind == "freq":
            return self._A_freq, self._d * (data[0] / (2 * np.pi) - self._f_a)
        build = qms_equations if kind == "qms" else fbm_equations
        return unit_weighted(build(self.K, self.M, *data, self.dKs, self.dMs, self.p_a))


CASES = {"simulated_free_pcb": SimulatedFreePCB, "board": StructureCase, "structure": StructureCase}
