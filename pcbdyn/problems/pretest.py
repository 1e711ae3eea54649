"""The pretest of a structure (board or box) from its model: sensors, their mass loading, the exciter and, for a
free structure, its suspension, read off the target modes at candidate points (:mod:`.pretest_points`);
the numerics are :mod:`pcbdyn.updating.design`'s. The perturbed configurations are :mod:`.pretest_configs`'.

The model is the structure's base configuration on its independent DOFs with the derivatives of the
parameters named, its target modes the first N elastic ones or those in a band.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from ..fe.assembly import assemble
from ..fe.constraints import build_reduction
from ..fe.modal import eigenpairs
from ..fe.probe import model_probe
from ..updating import design
from .models import parameter_derivatives
from .pretest_points import Candidates, is_box
from .system import ProblemError

@dataclass
class PretestModel:
    """One configuration of ``structure`` (``pm``, built) at its parameters' starting values ``p0`` [SI]:
    ``K``, ``M`` and the derivatives ``dKs``, ``dMs`` of the parameters ``names`` on the independent DOFs
    (``reduction``), the target modes' eigenvalues ``lam`` [rad^2/s^2] and shapes ``phi`` (mass-normalised),
    and the rigid-body modes ``rigid`` (a free structure's; (n, 0) otherwise); ``position``: each target's
    place among the elastic modes (0: the first), ``low_lam``, ``low_phi``: the two lowest elastic modes
    (those a suspension must leave alone first). The matrices are made once, at p0: a design is linear
    there."""

    structure: object
    pm: object
    names: list
    p0: np.ndarray
    K: sp.spmatrix
    M: sp.spmatrix
    dKs: list
    dMs: list
    reduction: object
    lam: np.ndarray = None
    phi: np.ndarray = None
    rigid: np.ndarray = None
    mesh_size: float | None = None
    position: np.ndarray = None
    low_lam: np.ndarray = None
    low_phi: np.ndarray = None

    @property
    def free(self) -> bool:
        return self.pm.model.free

    @property
    def frequencies(self) -> np.ndarray:
        return np.sqrt(self.lam) / (2 * np.pi)

    def matrices(self):
        return self.K, self.M, self.dKs, self.dMs

    def modes(self, extra_M=None, extra_K=None) -> tuple:
        """(eigenvalues, shapes) of the elastic modes at the targets' places (``position``; default the first
        ones) with ``extra_M``/``extra_K`` added (added masses, springs; sparse, independent DOFs)."""
        K = self.K if extra_K is None else self.K + extra_K
        M = self.M if extra_M is None else self.M + extra_M
        at = np.arange(self.lam.size) if self.position is None else self.position
        lam, vec, rigid = eigenpairs(K, M, n_modes=int(at.max()) + 1, free=self.free)
        order = np.argsort(lam[~rigid], kind="stable")[at]
        return lam[~rigid][order], vec[:, ~rigid][:, order]

    def read(self, xyz, directions) -> sp.csr_matrix:
        """P: the model read at points ``xyz`` (k, 3) along ``directions`` (k, 3), on the independent DOFs."""
        P = model_probe(self.pm.model, np.asarray(xyz, float), np.asarray(directions, float)).P
        return sp.csr_matrix(P @ self.reduction.T)

    def point_mass(self, xyz, mass: float) -> sp.csr_matrix:
        """The mass matrix of point masses ``mass`` [kg] at ``xyz`` (k, 3), moving with the shell's three
        translations there (interpolated as the test reads them)."""
        xyz = np.atleast_2d(np.asarray(xyz, float))
        P = self.read(np.repeat(xyz, 3, axis=0), np.tile(np.eye(3), (len(xyz), 1)))
        return sp.csr_matrix(mass * (P.T @ P))


def configuration_model(structure, config=None, names=(), mesh_size=None) -> PretestModel:
    """The :class:`PretestModel` of one configuration without modes: K, M by one assembly, the
    derivatives by central differences of the sets each parameter touches (one evaluation at p0: no
    interpolation of the matrices over the parameters' range is worth making)."""
    pm = structure.build(config, mesh_size)
    names = list(names)
    K, M = assemble(pm.model)
    red = build_reduction(pm.model, K, M)
    pairs = parameter_derivatives(pm, names)
    p0 = np.array([pm.parameters[n].value for n in names], float)
    return PretestModel(structure, pm, names, p0, red.reduce(K), red.reduce(M), [red.reduce(dK) for dK, _ in pairs],
                        [red.reduce(dM) for _, dM in pairs], red, mesh_size=mesh_size)


def pretest_model(structure, names=(), n_modes: int | None = None, band=None, mesh_size=None) -> PretestModel:
    """The :class:`PretestModel` of ``structure``'s base configuration: ``n_modes`` target modes (default the
    structure's [analysis] modes), or those in ``band`` = (lo, hi) [Hz]."""
    model = configuration_model(structure, None, names, mesh_size)
    n = structure.analysis.modes if n_modes is None and band is None else n_modes
    lam, vec, rigid = eigenpairs(model.K, model.M, n_modes=n, f_max=None if band is None else band[1],
                                 free=model.free)
    el = np.flatnonzero(~rigid)
    el = el[np.argsort(lam[el], kind="stable")]
    f = np.sqrt(np.clip(lam[el], 0, None)) / (2 * np.pi)
    position = np.flatnonzero((f >= band[0]) & (f <= band[1])) if band is not None else np.arange(min(n, el.size))
    if position.size == 0:
        raise ProblemError(f"{structure.path.name}: no elastic mode in {band[0]:g}-{band[1]:g} Hz; widen --band")
    tg, low = el[position], el[:2]
    return replace(model, lam=lam[tg], phi=vec[:, tg], rigid=vec[:, rigid], position=position, low_lam=lam[low],
                   low_phi=vec[:, low])


# --------------------------------------------------------------------------------------------- sensors
def sensor_directions(cand: Candidates, triaxial: bool) -> tuple:
    """(directions (n_rows, 3), the candidate of each row, code of each row): triaxial x, y, z at every
    point; uniaxial along the surface normal's axis (a board's z; a box plate's normal)."""
    if triaxial:
        d = np.tile(np.eye(3), (len(cand), 1))
        return d, np.repeat(np.arange(len(cand)), 3), ["+x", "+y", "+z"] * len(cand)
    axis = np.argmax(np.abs(cand.normal), axis=1)
    return np.eye(3)[axis], np.arange(len(cand)), [f"+{'xyz'[a]}" for a in axis]


@dataclass
class Sensors:
    """Chosen candidates ``chosen`` (indices into the candidates), the :class:`~pcbdyn.updating.design.SensorSet`
    behind them, and the measured rows: ``directions`` (n_rows, 3), ``codes`` and ``point`` (candidate of
    each row)."""

    chosen: np.ndarray
    result: design.SensorSet
    directions: np.ndarray
    codes: list
    point: np.ndarray


def choose_sensors(model: PretestModel, cand: Candidates, n_sensors: int, triaxial: bool,
                   max_automac: float = 0.25) -> Sensors:
    """EfI with the AutoMAC guard over the usable candidates (:func:`pcbdyn.updating.design.choose_sensors`)."""
    use = np.flatnonzero(cand.usable)
    dirs, point, codes = sensor_directions(cand, triaxial)
    rows = np.flatnonzero(np.isin(point, use))
    Phi = model.read(cand.xyz[point[rows]], dirs[rows]) @ model.phi
    try:
        res = design.choose_sensors(Phi, n_sensors, point[rows], max_automac)
    except ValueError as exc:
        raise ProblemError(f"--sensors: {exc}") from None
    chosen = np.unique(point[rows])[res.chosen]
    keep = np.flatnonzero(np.isin(point, chosen))
    return Sensors(chosen, res, dirs[keep], [codes[i] for i in keep], point[keep])


def mass_loading(model: PretestModel, xyz, sensor_mass: float) -> dict:
    """What sensors of ``sensor_mass`` [kg] at ``xyz`` do to the target modes: the relative frequency shift
    [%] to first order, -1/2 m sum phi^2 over their three translations (mass-normalised modes, the
    Rayleigh quotient), and re-solved with the masses on."""
    P = model.read(np.repeat(xyz, 3, axis=0), np.tile(np.eye(3), (len(xyz), 1)))
    first = -50.0 * sensor_mass * np.sum(np.asarray(P @ model.phi) ** 2, axis=0)
    lam, _ = model.modes(extra_M=model.point_mass(xyz, sensor_mass))
    return {"sensor_mass_kg": sensor_mass, "first_order_pct": first,
            "shift_pct": 100.0 * (np.sqrt(lam / model.lam) - 1.0)}


# --------------------------------------------------------------------------------------------- exciter
def choose_exciter(model: PretestModel, cand: Candidates) -> dict:
    """The usable candidate and direction (a board: its normal; a box, whose modes live on different plates:
    x, y or z) whose smallest driving-point share over the target modes is largest
    (:func:`pcbdyn.updating.design.best_exciter`)."""
    dirs, point, codes = sensor_directions(cand, is_box(model.structure))
    Phi = model.read(cand.xyz[point], dirs) @ model.phi
    j, share = design.best_exciter(Phi, cand.usable[point])
    return {"index": int(point[j]), "direction": codes[j], "share": share}


# ------------------------------------------------------------------------------------------ suspension
@dataclass
class Suspension:
    """Suspension springs of a free structure: ``chosen`` candidates (springs along the global z), the
    stiffness ``k`` [N/m] of each, the suspension modes' frequencies predicted on the rigid-body modes
    (``predicted_hz``) and re-solved with the springs on (``solved_hz``, the lowest six), the target
    modes with the springs (``elastic_hz``) and the share of the first elastic mode aimed at."""

    chosen: np.ndarray
    k: float
    predicted_hz: np.ndarray
    solved_hz: np.ndarray
    elastic_hz: np.ndarray
    target_share: float

    def shift_pct(self, free_hz) -> np.ndarray:
        return 100.0 * (self.elastic_hz / np.asarray(free_hz) - 1.0)


def springs(model: PretestModel, xyz, k: float) -> sp.csr_matrix:
    """The stiffness of springs ``k`` [N/m] to ground along z at ``xyz`` (k, 3)."""
    P = model.read(xyz, np.tile([0.0, 0.0, 1.0], (len(xyz), 1)))
    return sp.csr_matrix(k * (P.T @ P))


def choose_suspension(model: PretestModel, cand: Candidates, share: float = 0.1, max_shift_pct: float = 0.1,
                      n_points: int = 4) -> Suspension:
    """Springs along z at ``n_points`` candidates near the nodal lines of the two lowest elastic modes, spread
    so that they hold every rigid motion they can (:func:`pcbdyn.updating.design.spread_points`), of the
    stiffness that puts the highest suspension mode at ``share`` of the first elastic mode, or less where
    that would shift one of those two or a target mode by more than ``max_shift_pct`` to first order
    (50 k sum phi^2 / lambda %); then solved again with the springs on (the suspension modes are the six
    lowest, the targets keep their places among the elastic modes)."""
    if not model.free:
        raise ProblemError(f"{model.structure.path.name}: the structure is held by its supports; a suspension is "
                           "for a free one")
    z = np.tile([0.0, 0.0, 1.0], (len(cand), 1))
    at = np.asarray(model.read(cand.xyz, z) @ np.column_stack([model.low_phi, model.phi, model.rigid]))
    n_low, n_t = model.low_lam.size, model.lam.size
    low, R = at[:, :n_low], at[:, n_low + n_t:]
    use = np.flatnonzero(cand.usable)
    pick = use[design.spread_points(design.nodal_score(low[use]), R[use], n_points)]
    unit = design.spring_share(R[pick])
    omega = share * float(np.sqrt(model.low_lam[0]))
    lam_all = np.r_[model.low_lam, model.lam]
    shift_per_k = float(np.max(50.0 * np.sum(at[pick, :n_low + n_t] ** 2, axis=0) / lam_all))
    k = min(omega**2 / float(unit.max()), max_shift_pct / shift_per_k)
    K, M, _, _ = model.matrices()
    lam, _, _ = eigenpairs(K + springs(model, cand.xyz[pick], k), M, n_modes=int(model.position.max()) + 7,
                           free=True)
    f = np.sqrt(np.clip(np.sort(lam), 0, None)) / (2 * np.pi)
    return Suspension(pick, k, np.sqrt(k * unit) / (2 * np.pi), f[:6], f[6 + model.position], share)
