"""Success-ratio studies of parameter error localisation (thesis sections 5.3-5.4, 6.4.2).

A *case* knows its parameters, its true errors and how to build weighted updating equations
A x = b from noisy simulated test data (:meth:`SimulatedFreePCB.equations`). :func:`run_study`
localises over noise levels x random shots x methods x equation types, in parallel processes,
and returns one row per localisation; :func:`summarise` gives the mean and standard deviation of
the success ratio (eq. 5.66) per equation type, method and noise level.

Methods (all see the same noisy equations of a shot):

- ``tls-qrf``: :func:`~.subset.tls_qrf` (thesis 5.2.3), b weighted for TLS (eq. 4.43) by the
  errors the stated noise level makes in A and b, measured by drawing that noise again on the
  shot's data (:func:`~.weighting.tls_column_weight_from_noise`): the study states the level,
  as a tester states the precision of a measurement;
- ``svd-qr``: :func:`~.subset.svd_qr` (5.2.2);
- ``qr``: :func:`~.subset.qr_basic_solution` with the threshold of eq. 5.64;
- ``min-norm``: the minimum-norm LS solution of all parameters at the full numerical rank (only
  singular values below RTOL sigma_1 are dropped; no epsilon-condition cut and never the chosen
  ``rank``: "for minimal 2-norm method, the numerical rank number is always set to 18", thesis
  5.4.1, QMS), judged by the same threshold as the others (eq. 5.64: |x_i| above
  max(0.01, 0.2 max|x|)). This is how the thesis counts N_det of its "minimal 2-norm" solution
  (section 5.4.1: 16 of 18 moduli detected).
"""

from __future__ import annotations

import os
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import replace

import numpy as np
import pandas as pd

from .equations import fbm_equations, frf_receptance_equations, qms_equations
from .pbc import stack
from .sensitivity import frequencies_hz, solve_modes
from .solvers import RankDeficiencyWarning, solve_ls
from .subset import qr_basic_solution, svd_qr, threshold_selection, tls_qrf
from .success import add_noise, success_ratio, success_statistics
from .weighting import NOISE_REDRAWS, tls_column_weight_from_noise, unit_row_weights, weight_rows

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
METHODS = ("tls-qrf", "svd-qr", "qr", "min-norm")


def _rank(rank, n):
    """None: automatic; k >= 0: k; k < 0: n + k (e.g. -1 = one below full, the thesis' free PCB)."""
    if rank is None:
        return None
    return int(rank) if rank >= 0 else n + int(rank)


def localise(method: str, A, b, rank: int | None = None, t_b: float | None = None) -> np.ndarray:
    """Indices of the parameters ``method`` (see the module doc) detects as erroneous; ``t_b``:
    TLS weight of b (default eq. 4.43 with k_A = k_b)."""
    r = _rank(rank, A.shape[1])
    if method == "tls-qrf":
        return tls_qrf(A, b, rank=r, t_b=t_b).selected
    if method == "svd-qr":
        return svd_qr(A, b, rank=r).selected
    if method == "qr":
        return threshold_selection(qr_basic_solution(A, b, rank=r).x)
    if method == "min-norm":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RankDeficiencyWarning)
            # full numerical rank (thesis 5.4.1): no jump of the epsilon-condition curve is cut
            return threshold_selection(solve_ls(A, b, jump=np.inf).x)
    raise ValueError(f"method {method!r}: choose one of {', '.join(METHODS)}")


def compress(A, b):
    """(R[:, :n], R[:, n]) from the QR factorisation [A b] = Q R: n + 1 rows that keep every
    quantity the localisation methods use (singular values and right singular vectors of A and
    of [A b], ||A||_F, ||b||, least-squares solutions, the part of b outside range(A)), so tall
    FRF blocks cost no more than small ones."""
    if A.shape[0] <= A.shape[1] + 1:
        return A, b
    R = np.linalg.qr(np.column_stack([A, b]), mode="r")
    return R[:, :-1], R[:, -1]


def _weighted(blk):
    """Unit-row-weighted equations (eq. 4.42) without the all-zero rows (e.g. the imaginary
    rows of undamped FRF equations)."""
    keep = np.linalg.norm(blk.A, axis=1) > 0
    A, b = blk.A[keep], blk.b[keep]
    return weight_rows(A, b, unit_row_weights(A))


class _Case:
    """What :func:`run_study` asks of a case: ``measure`` (noisy test data), ``build`` (weighted
    equations from data), hence ``equations``."""

    def equations(self, kind: str, level_pct: float, rng):
        """Weighted (A, b) of equation type ``kind`` from test data with ``level_pct`` % uniform
        noise (eqs. 5.72-5.74)."""
        return self.build(kind, self.measure(kind, level_pct, rng))


class SimulatedFreePCB(_Case):
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

    def __init__(self, nu: float = 0.35, n_modes: int = 7, errors_mm: dict | None = None,
                 excitation_node: int = 43, perturbation_node: int = 56, perturbation_kg: float = 0.01,
                 freq_margin: float = 0.03):
        from ..fe.assembly import element_matrices, scatter
        from ..fe.generate import rectangle
        from ..fe.model import Model
        from ..fe.properties import ShellProperty
        from ..fe.reduction import guyan

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
                raise ValueError(f"errors_mm: element {k} does not exist; elements are 1..{n_el}")
            self.p_x[int(k) - 1] = float(v) * 1e-3
        self.true_errors = np.flatnonzero(np.abs(self.p_x / self.p_a - 1) > 1e-12)
        if self.true_errors.size == 0:
            raise ValueError("errors_mm: no element differs from the model (p_a): nothing to localise")

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
        for key, node in (("excitation_node", excitation_node), ("perturbation_node", perturbation_node)):
            if not 1 <= int(node) <= nn:
                raise ValueError(f"{key} = {node}: thesis node numbers run 1..{nn} (n = 8 ix + iy + 1, Fig. 5.41)")
        self.excitation = int(self.node_of[excitation_node - 1])
        dm = np.zeros(nn)
        dm[self.node_of[perturbation_node - 1]] = perturbation_kg
        self.configs = []
        for added in (np.zeros(nn), dm):
            Mc, Mxc = self.M + np.diag(added), Mx + np.diag(added)
            lam_a, _ = solve_modes(self.K, Mc)
            lam_x, phi_x = solve_modes(Kx, Mxc)
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
        if kind in ("frf", "frf+pbc"):
            return tuple(add_noise(c["H_x"], level_pct, rng) for c in self.configs[: 1 if kind == "frf" else 2])
        raise ValueError(f"equation type {kind!r}: choose one of {', '.join(self.kinds)}")

    def build(self, kind: str, data: tuple):
        """Weighted (A, b) of equation type ``kind`` from test data (:meth:`measure`)."""
        if kind in ("qms", "fbm"):
            build = qms_equations if kind == "qms" else fbm_equations
            return _weighted(build(self.K, self.configs[0]["M"], *data, self.dKs, self.dMs, self.p_a))
        return tuple(stack([_weighted(frf_receptance_equations(
            self.K, c["M"], c["omegas"], H, self.excitation, self.dKs, self.dMs, self.p_a))
            for c, H in zip(self.configs, data)]))


class BoardCase(_Case):
    """A success-ratio case from any board.toml: its ``[[parameters]]`` (or ``params``) at their
    board values are the model, ``truth`` ({name: value, SI or a string with units}) the
    simulated structure, measured at the points of ``points_csv`` (first ``n_modes`` elastic
    modes, paired in order; checked by MAC).

    Like the thesis' reduced models, the model and its derivatives are condensed once onto the
    measured DOFs (:func:`~.matching.reduce_system`), so each noisy shot only rebuilds small
    equations: ``qms``, ``fbm`` or ``freq`` (eigenvalue sensitivities of the full model; noise
    enters b only).
    """

    kinds = ("qms", "fbm", "freq")

    def __init__(self, board_toml, truth: dict, points_csv, n_modes: int = 6, params=None):
        from ..board import load_board
        from ..testdata import read_points_csv
        from ..units import to_si
        from . import matching
        from .board_problem import BoardProblem
        from .equations import frequency_equations
        from .iteration import mac_matrix

        problem = BoardProblem(load_board(board_toml), params)
        self.parameter_names = list(problem.names)
        self.p_a = problem.p0.copy()
        self.p_x = self.p_a.copy()
        if not truth:
            raise ValueError("truth: give the true value of at least one parameter, e.g. t_U1 = \"4 mm\"")
        for name, value in truth.items():
            if name not in self.parameter_names:
                raise ValueError(f"truth: {name!r} is not a parameter (known: {', '.join(self.parameter_names)})")
            i = self.parameter_names.index(name)
            self.p_x[i] = to_si(value, problem.units[i], f"truth.{name}") if isinstance(value, str) else float(value)
        self.true_errors = np.flatnonzero(np.abs(self.p_x / self.p_a - 1) > 1e-12)
        if self.true_errors.size == 0:
            raise ValueError("truth: every value equals the board's: nothing to localise")
        points, dofs = read_points_csv(points_csv)
        sysm = problem.system(None)
        P = sysm.measurement_matrix(points.xyz[points.index(dofs.point_ids)], dofs.directions)
        nr, el = sysm.n_rigid, slice(sysm.n_rigid, sysm.n_rigid + int(n_modes))
        Kx, Mx, _, _ = sysm.model(self.p_x)
        lam_x, phi_full = solve_modes(Kx, Mx, nr + int(n_modes))
        K, M, dKs, dMs = sysm.model(self.p_a)
        lam_a, Phi_a = solve_modes(K, M, nr + int(n_modes))
        self.omega_x, self.phi_x = np.sqrt(lam_x[el]), np.asarray(P @ phi_full[:, el])
        mac = np.diag(mac_matrix(np.asarray(P @ Phi_a[:, el]), self.phi_x))
        if np.any(mac < 0.8):
            raise ValueError(f"truth: the true board's modes do not pair in order with the model's (MAC "
                             f"{np.round(mac, 2).tolist()}); use smaller errors or fewer modes (n_modes)")
        self.K, self.M, self.dKs, self.dMs = matching.reduce_system(K, M, dKs, dMs, P)
        blk = frequency_equations(lam_a[el], Phi_a[:, el], frequencies_hz(lam_x[el]), dKs, dMs, self.p_a)
        self._d = unit_row_weights(blk.A)
        self._A_freq = blk.A * self._d[:, None]
        self._f_a = frequencies_hz(lam_a[el])

    def measure(self, kind: str, level_pct: float, rng) -> tuple:
        """(omega,) or (omega, shapes) of the simulated test with ``level_pct`` % uniform noise
        (eqs. 5.72-5.73) drawn from ``rng``."""
        if kind not in self.kinds:
            raise ValueError(f"equation type {kind!r}: choose one of {', '.join(self.kinds)}")
        om = add_noise(self.omega_x, level_pct, rng)
        return (om,) if kind == "freq" else (om, add_noise(self.phi_x, level_pct, rng))

    def build(self, kind: str, data: tuple):
        """Weighted (A, b) of equation type ``kind`` from test data (:meth:`measure`); the
        frequency equations' A comes from the model alone (noise enters b only)."""
        if kind == "freq":
            return self._A_freq, self._d * (data[0] / (2 * np.pi) - self._f_a)
        build = qms_equations if kind == "qms" else fbm_equations
        return _weighted(build(self.K, self.M, *data, self.dKs, self.dMs, self.p_a))



CASES = {"simulated_free_pcb": SimulatedFreePCB, "board": BoardCase}

_CASE = None


def _init(case):
    global _CASE
    _CASE = case


def _run_batch(kind, level, shots, methods, seed, rank, case=None):
    case = _CASE if case is None else case
    rows = []
    for shot in shots:
        key = [seed, case.kinds.index(kind), int(round(level * 1e6)), shot]
        data = case.measure(kind, level, np.random.default_rng(key))
        A, b = case.build(kind, data)
        t_b = None
        if "tls-qrf" in methods:
            redraw = np.random.default_rng(key + [1])
            t_b = tls_column_weight_from_noise(A, b, [
                case.build(kind, tuple(add_noise(d, level, redraw) for d in data)) for _ in range(NOISE_REDRAWS)])
        A, b = compress(A, b)
        for method in methods:
            sel = localise(method, A, b, rank, t_b)
            rows.append({
                "equations": kind, "level_pct": level, "shot": shot, "method": method,
                "success_ratio": success_ratio(sel, case.true_errors), "n_detected": int(sel.size),
                "n_true_detected": int(np.isin(sel, case.true_errors).sum()),
                "selected": " ".join(case.parameter_names[i] for i in sel),
            })
    return rows


def run_study(case, levels, shots: int = 20, methods=("tls-qrf", "svd-qr", "min-norm"), kinds=("qms",),
              seed: int = 0, rank: int | None = None, workers: int | None = None, progress: bool = True,
              batch: int = 5) -> pd.DataFrame:
    """Localise on ``shots`` noisy data sets per noise level (%) and equation type with every
    method; one DataFrame row per (equations, level_pct, shot, method). Shot noise is seeded
    from (seed, equation type, level, shot), so results do not depend on ``workers``.
    ``workers``: processes (default all cores; 1 runs in this process). ``rank``: None
    (automatic), k >= 0 or k < 0 meaning n_params + k, for the rank-based methods."""
    for m in methods:
        if m not in METHODS:
            raise ValueError(f"methods: {m!r} is unknown; choose from {', '.join(METHODS)}")
    for k in kinds:
        if k not in case.kinds:
            raise ValueError(f"equations: {k!r} is unknown for this case; choose from {', '.join(case.kinds)}")
    if shots < 1:
        raise ValueError("shots must be >= 1")
    jobs = [(k, float(lv), list(range(s, min(s + batch, shots))), tuple(methods), seed, rank)
            for k in kinds for lv in levels for s in range(0, shots, batch)]
    total = len(kinds) * len(levels) * shots
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    from tqdm import tqdm

    rows = []
    with tqdm(total=total, unit="shot", disable=not progress, desc="localisation study") as bar:
        if workers <= 1:
            for job in jobs:
                rows += _run_batch(*job, case=case)
                bar.update(len(job[2]))
        else:
            with ProcessPoolExecutor(max_workers=workers, initializer=_init, initargs=(case,)) as pool:
                futures = {pool.submit(_run_batch, *job): job for job in jobs}
                for fut in as_completed(futures):
                    rows += fut.result()
                    bar.update(len(futures[fut][2]))
    df = pd.DataFrame(rows)
    return df.sort_values(["equations", "method", "level_pct", "shot"], ignore_index=True)


def summarise(df: pd.DataFrame) -> pd.DataFrame:
    """Mean and sample standard deviation of the success ratio (eq. 5.66) per equation type,
    method and noise level, with the number of shots."""
    out = []
    for (kind, method, level), g in df.groupby(["equations", "method", "level_pct"], sort=True):
        mean, std = success_statistics(g["success_ratio"].to_numpy())
        out.append({"equations": kind, "method": method, "level_pct": level, "mean": mean, "std": std,
                    "shots": len(g)})
    return pd.DataFrame(out)
