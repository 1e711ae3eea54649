"""The residual of a model against modal tests, in units of noise, and its first-order sensitivity to
declared parameters and to candidate effects (issue 7, steps 2 and 5).

Rows, per test configuration: one per measured mode,
    r_i = (f_x,i - c_i f_a,i) / (sigma_f,i f_x,i),
c_i being the model's discretisation correction of the mode (1 when none is known), and, with measured shapes, one per point and mode,
    r_ji = (phi_x,ji - s_i u_ji) / (sigma_s,i rms(phi_x,i)),
u_i being the paired model shape read at the points and s_i its modal scale factor (the
least-squares fit of u_i to phi_x,i), so that the shape counts and not its scaling. With the right
sigmas, chi^2 = |r|^2 of a model that lacks nothing is a chi-square variable.

Sensitivities: the eigenvalue derivative (thesis eq. 3.6) for the frequency rows, and for the
shape rows the modal expansion of the eigenvector derivative over every computed mode, rigid-body
modes included (eqs. 3.8-3.14): d phi_i = sum_(k != i) phi_k phi_k^T (dK - lambda_i dM) phi_i /
(lambda_i - lambda_k); the part along phi_i only rescales the shape and drops out with s_i. Both
need only the bilinear forms phi_k^T dK phi_i, phi_k^T dM phi_i (:func:`.catalogue.effect_forms`
for candidates, sparse products for parameters). The truncated expansion makes the columns
approximate; every fit is confirmed on full re-solves.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..correlation.close_modes import align_close, close_groups
from ..correlation.mac import paired_mac
from ..correlation.pairing import pair_modes
from ..fe.assembly import assemble
from ..fe.modal import solve_modes
from ..fe.probe import model_probe
from ..parallel import beside, spare
from ..testdata import MeasuredModes
from ..updating.sensitivity import bilinear_forms, eigen_derivatives
from .catalogue import effect_forms
from .combined import Effects


#: [m] farthest a test point may lie from the model's surface and still be read (a point on a
#: coarse mesh's chord of a curved outline)
READ_TOL = 0.02


def reading(model, xyz, directions):
    """The matrix (points x DOFs) that reads ``model``'s displacements at test points ``xyz`` [m]
    along ``directions``, through the shell shape functions."""
    return model_probe(model, xyz, directions, tol=READ_TOL).P


@dataclass(frozen=True)
class Observation:
    """One test configuration in the residual: its measured ``modes`` (:class:`pcbdyn.testdata.MeasuredModes`:
    frequencies, and shapes that the model gives as ``read @ u``, ``read`` (n_pts, n_dof) on the full
    DOFs); relative standard deviations ``sigma_f`` (m,) of the frequencies and ``sigma_s`` (m,) of a
    shape component (per RMS of the mode's measured shape); ``f_scale`` (m,): the factor that takes the
    paired model frequency to its converged-mesh value (a discretisation correction; 1 by default);
    ``noise_f`` (m,): the measurement's share of ``sigma_f``, which tells close modes apart (None
    until the noise is known: no modes are then close).
    Without shapes the modes pair by order. Never changed once made: a new error budget is a new
    observation (``dataclasses.replace``) in a new residual (:meth:`ModalResidual.on`)."""

    name: str | None
    modes: MeasuredModes
    sigma_f: np.ndarray
    read: object = None
    sigma_s: np.ndarray | None = None
    f_scale: np.ndarray | None = None
    noise_f: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "sigma_f", np.asarray(self.sigma_f, float))
        if self.f_scale is None:
            object.__setattr__(self, "f_scale", np.ones(self.f.size))

    @property
    def f(self) -> np.ndarray:
        return self.modes.frequencies

    @property
    def shapes(self) -> np.ndarray | None:
        return self.modes.shapes

    @property
    def numbers(self) -> np.ndarray:
        return self.modes.numbers

    def read_on(self, model) -> "Observation":
        """This observation (noise and correction kept) read on ``model``'s mesh."""
        return replace(self, read=None if self.shapes is None else reading(model, self.modes.xyz, self.modes.directions))

    def subset(self, keep) -> "Observation":
        """The observation of the measured modes ``keep`` (a boolean mask or indices)."""
        k = np.asarray(keep)
        return Observation(self.name, self.modes.subset(k), self.sigma_f[k], self.read,
                           None if self.sigma_s is None else self.sigma_s[k], self.f_scale[k],
                           None if self.noise_f is None else self.noise_f[k])

    @property
    def n_rows(self) -> int:
        return self.f.size * (1 + (0 if self.shapes is None else self.shapes.shape[0]))


@dataclass
class ConfigState:
    """A configuration's model at one state: its matrices ``K``, ``M`` (with the effects),
    ``modes``, ``pairs`` (elastic mode index per measured mode; ``matched`` False where no model
    mode resembles it and the nearest free one stands in), paired frequencies ``f_a`` (with the
    observation's discretisation correction), ``mac``, the
    model shapes at the points ``u`` and scale factors ``s``, its rows ``r``; ``points``: the modes
    [rigid, elastic] at the measured points when they are not read from full-length shapes (a
    state found by :mod:`.reanalysis`); ``x``: the measured shapes the rows compare, ``close``: the
    groups of close modes among them that were turned onto the model's
    (:func:`pcbdyn.correlation.close_modes.align_close`)."""

    model: object
    K: object
    M: object
    modes: object
    pairs: np.ndarray
    matched: np.ndarray
    f_a: np.ndarray
    mac: np.ndarray
    u: np.ndarray | None
    s: np.ndarray | None
    r: np.ndarray
    points: np.ndarray | None = None
    x: np.ndarray | None = None  # the measured shapes as compared: each close group turned onto its model modes
    close: tuple = ()  # the groups of close measured modes whose shapes were turned
    static: tuple | None = None  # (reduction, shift, factorisation) of :func:`beyond_basis`, made when first needed

    def at_points(self, read) -> np.ndarray:
        """The modes [rigid, elastic] at the measured points (``read``: the observation's reading)."""
        if self.points is not None:
            return self.points
        return np.asarray(read @ np.column_stack([self.modes.rigid_shapes, self.modes.shapes]))


@dataclass
class State:
    """Declared parameter values ``p`` [SI], effects (``candidates``, ``values`` [SI]) and the
    per-configuration states."""

    p: np.ndarray
    candidates: list
    values: np.ndarray
    configs: list = field(default_factory=list)

    @property
    def r(self) -> np.ndarray:
        return np.concatenate([c.r for c in self.configs])

    @property
    def chi2(self) -> float:
        r = self.r
        return float(r @ r)

    def summary(self, observations) -> dict:
        """Max |frequency error| [%] and mean MAC over all configurations, and per configuration, of
        the test modes paired with a model mode (``paired``; the others, with the nearest free
        frequency standing in, are listed in ``unpaired_test_modes``: a support's bounce on a free
        model that lacks it, :mod:`.support`; groups of close test modes compared as a plane, their
        MAC after the turn, in ``close_test_modes``)."""
        per = []
        for ob, c in zip(observations, self.configs):
            df = 100.0 * (c.f_a / ob.f - 1.0)
            use = c.matched if c.matched.any() else np.ones(c.matched.size, bool)
            entry = {"configuration": ob.name or "base", "max_freq_error_pct": float(np.max(np.abs(df[use]))),
                     "mean_mac": float(np.mean(c.mac[use])) if ob.shapes is not None else None,
                     "modes": [{"test_mode": int(ob.numbers[i]), "model_mode": int(c.pairs[i]) + 1,
                                "f_test_hz": float(ob.f[i]),
                                "f_model_hz": float(c.f_a[i]), "df_pct": float(df[i]),
                                "mac": float(c.mac[i]) if ob.shapes is not None else None, "paired": bool(c.matched[i])}
                               for i in range(ob.f.size)]}
            if not c.matched.all():
                entry["unpaired_test_modes"] = [int(n) for n in ob.numbers[~c.matched]]
            if c.close:
                entry["close_test_modes"] = [[int(ob.numbers[i]) for i in g] for g in c.close]
            per.append(entry)
        macs = [q["mean_mac"] for q in per if q["mean_mac"] is not None]
        return {"max_freq_error_pct": max(q["max_freq_error_pct"] for q in per),
                "mean_mac": float(np.mean(macs)) if macs else None, "configurations": per}


def paired_state(ob: Observation, model, K, M, modes, U, points=None) -> ConfigState:
    """The state of observation ``ob`` against model ``modes`` (frequencies, and ``U`` their shapes at
    the points, None without measured shapes): test modes paired by MAC (the nearest free frequency
    standing in where none resembles), modal scale factors and residual rows. ``points``: the
    points' basis of the modes' derivatives when it is not ``ob.read`` on full-length shapes."""
    m = ob.f.size
    f_all = modes.frequencies
    if U is None:
        pairs = np.arange(m)
        matched = np.ones(m, bool)
        u = s = None
        macs = np.ones(m)
    else:
        pairs = -np.ones(m, int)
        for pr in pair_modes(ob.shapes, U, ob.f, f_all, min_mac=0.3).pairs:
            if pr.used:  # a pair beyond the frequency limit is left to the nearest free frequency below
                pairs[pr.test] = pr.model
        matched = pairs >= 0
        seen = np.linalg.norm(U, axis=0) > 1e-6 * np.linalg.norm(U, axis=0).max()  # not a mode the points miss
        free = [k for k in range(f_all.size) if k not in set(pairs.tolist()) and seen[k]]
        for i in np.flatnonzero(pairs < 0):  # unpaired: nearest unused frequency keeps the rows defined
            k = min(free, key=lambda k: abs(f_all[k] / ob.f[i] - 1))
            pairs[i] = k
            free.remove(k)
        u = U[:, pairs]
        groups = [] if ob.noise_f is None else close_groups(ob.f, ob.noise_f * ob.f)
        close = tuple(g for g in groups if matched[list(g)].all())
        x = align_close(ob.shapes, u, close)
        with np.errstate(divide="ignore", invalid="ignore"):  # a paired mode the points miss: rows not finite,
            s = np.sum(u * x, axis=0) / np.sum(u * u, axis=0)  # a state the fits refuse (.fitting)
        macs = paired_mac(u, x)
    f_a = f_all[pairs] * ob.f_scale
    rows = [(ob.f - f_a) / (ob.sigma_f * ob.f)]
    if u is None:
        return ConfigState(model, K, M, modes, pairs, matched, f_a, macs, u, s, rows[0], points)
    rms = np.sqrt(np.mean(x**2, axis=0))
    rows.append(((x - s * u) / (ob.sigma_s * rms)).T.ravel())
    return ConfigState(model, K, M, modes, pairs, matched, f_a, macs, u, s, np.concatenate(rows), points, x, close)


class ModalResidual:
    """Residual rows of ``observations`` against the models ``build(p)`` (one fe.Model per
    observation, all on one mesh, so that a candidate's nodes mean the same in each) carrying
    effects. ``derivatives(p, models)``: per observation, one (dK, dM) pair (full size) per declared
    parameter, or None when there are none."""

    @classmethod
    def of_models(cls, models, observations) -> "ModalResidual":
        """The residual of ``observations`` against a structure's configuration models as functions of
        its declared parameters (:class:`pcbdyn.problems.StructureModels`)."""
        return cls(observations, models.build, models.derivatives if models.names else None, len(models.names),
                   models.matrices)

    def __init__(self, observations, build, derivatives=None, n_params: int = 0, matrices=None):
        """``matrices(p)``: per observation, its model's (K, M) at ``p`` (default: assembled from
        ``build(p)``)."""
        self.observations = list(observations)
        self.build = build
        self.derivatives = derivatives
        self.n_params = n_params
        self.matrices = matrices
        self.n_rows = sum(o.n_rows for o in self.observations)
        self.effects = Effects()
        self._at = (None, None)  # last p, its [(model, K, M)]
        self._seconds: dict = {}  # per configuration, how long its last solve took

    def on(self, observations) -> "ModalResidual":
        """This residual of ``observations``: the same configurations' measured modes with another error
        budget (noise, mesh correction); the models, their assembled matrices and the effects' patterns
        are shared."""
        other = ModalResidual(observations, self.build, self.derivatives, self.n_params, self.matrices)
        other.effects, other._at, other._seconds = self.effects, self._at, self._seconds
        return other

    def row_groups(self) -> tuple:
        """(configuration index, mode index) of every row: the blocks cross-validation leaves out."""
        cfg, mode = [], []
        for k, ob in enumerate(self.observations):
            m = ob.f.size
            n_pts = 0 if ob.shapes is None else ob.shapes.shape[0]
            cfg.append(np.full(m * (1 + n_pts), k))
            mode.append(np.r_[np.arange(m), np.repeat(np.arange(m), n_pts)])
        return np.concatenate(cfg), np.concatenate(mode)

    # --- states ----------------------------------------------------------------------------
    def _assembled(self, p):
        if self._at[0] is None or not np.array_equal(self._at[0], p):
            models = self.build(p)
            mats = self.matrices(p) if self.matrices is not None else [assemble(m) for m in models]
            self._at = (p.copy(), [(m, *km) for m, km in zip(models, mats)])
        return self._at[1]

    def evaluate(self, p, candidates=(), values=()) -> State:
        """Full re-solve of every configuration at parameters ``p`` with the effects. The effects
        enter K and M linearly, so their exact derivative matrices are added to the model's
        (made once per p, on one pattern per set of effects: :class:`.combined.Effects`); the
        configuration states keep the model without them."""
        p = np.asarray(p, float)
        st = State(p, list(candidates), np.asarray(values, float))
        systems = [(ob, model, *self.effects.combine(k, model, K, M, p, candidates, st.values))
                   for k, (ob, (model, K, M)) in enumerate(zip(self.observations, self._assembled(p)))]
        for (ob, model, K, M), modes in zip(systems, self._solved(systems)):
            U = None if ob.shapes is None else np.asarray(ob.read @ modes.shapes)
            st.configs.append(paired_state(ob, model, K, M, modes, U))
        return st

    def _solved(self, systems) -> list:
        """The modes of every configuration's (model, K, M). With spare cores
        (:func:`pcbdyn.parallel.spare_cores`) the configurations are shared out by their last solve's
        time, the longest first, each to the least loaded process, this one first among equals (a
        declared mass off the board's plane couples its bending and membrane DOFs, and that
        configuration's solve takes twice the others')."""
        loads = [0.0] * (spare() + 1)
        where = {}
        for k in sorted(range(len(systems)), key=lambda k: -self._seconds.get(k, 0.0)):
            where[k] = int(np.argmin(loads))
            loads[where[k]] += self._seconds.get(k, 1.0)
        away = {k: beside(_timed_modes, model, self.n_modes(ob), K, M)
                for k, (ob, model, K, M) in enumerate(systems) if where[k]}
        done = {k: _timed_modes(model, self.n_modes(ob), K, M)
                for k, (ob, model, K, M) in enumerate(systems) if not where[k]}
        done.update((k, f.result()) for k, f in away.items())
        self._seconds.update((k, t) for k, (_, t) in done.items())
        return [done[k][0] for k in range(len(systems))]

    @staticmethod
    def n_modes(ob: Observation) -> int:
        """How many elastic modes a configuration's state holds: twice the measured ones (pairing
        and the modal expansion of the shape derivatives)."""
        return max(2 * ob.f.size, ob.f.size + 6)

    # --- sensitivities ---------------------------------------------------------------------
    def _columns(self, ob: Observation, cs: ConfigState, BK, BM, dU_static=None) -> np.ndarray:
        """Rows of d(model prediction)/d(parameter) in noise units from bilinear forms
        BK, BM (n_col, n_basis, m) over the basis [rigid, elastic] and the paired modes;
        ``dU_static`` (n_pts, m, n_col): the shape derivatives' part from the modes beyond the basis."""
        modes = cs.modes
        nr = modes.n_rigid
        dlam, C = eigen_derivatives(BK, BM, np.r_[np.zeros(nr), modes.omega2], nr + cs.pairs, cs.close)  # (n_col, m)
        df = dlam * ob.f_scale**2 / (8.0 * np.pi**2 * cs.f_a)  # d(c f)/dp, f = f_a / c
        out = [(df / (ob.sigma_f * ob.f)).T]
        if cs.u is not None:
            Ub = cs.at_points(ob.read)
            dU = np.einsum("pk,cki->pic", Ub, C, optimize=True)  # (n_pts, m, n_col)
            if dU_static is not None:
                dU = dU + dU_static
            uh = cs.u / np.linalg.norm(cs.u, axis=0)
            dU -= uh[:, :, None] * np.einsum("pi,pic->ic", uh, dU)[None]
            rms = np.sqrt(np.mean(cs.x**2, axis=0))
            dU *= (cs.s / (ob.sigma_s * rms))[None, :, None]
            out.append(dU.transpose(1, 0, 2).reshape(-1, dU.shape[2]))
        return np.vstack(out)

    @staticmethod
    def _basis(cs):
        return np.column_stack([cs.modes.rigid_shapes, cs.modes.shapes]), cs.modes.shapes[:, cs.pairs]

    def effect_columns(self, st: State, candidates) -> np.ndarray:
        """(n_rows, n_candidates): d(prediction)/d(magnitude) per SI unit of each candidate."""
        if not candidates:
            return np.zeros((self.n_rows, 0))
        out = []
        for ob, cs in zip(self.observations, st.configs):
            basis, paired = self._basis(cs)
            BK, BM = effect_forms(cs.model, basis, paired, candidates, self.effects.blocks)
            out.append(self._columns(ob, cs, BK, BM))
        return np.vstack(out)

    def param_columns(self, st: State) -> np.ndarray:
        """(n_rows, n_params): d(prediction)/d(ln p) of the declared parameters."""
        if not self.n_params:
            return np.zeros((self.n_rows, 0))
        out = []
        for ob, cs, pairs in zip(self.observations, st.configs, self.derivatives(st.p, [c.model for c in st.configs])):
            basis, paired = self._basis(cs)
            BK, BM = bilinear_forms(basis, paired, [dK for dK, _ in pairs], [dM for _, dM in pairs])
            static = None
            if cs.u is not None:
                lam = cs.modes.omega2[cs.pairs]
                F = np.stack([dK @ paired - (dM @ paired) * lam[None, :] for dK, dM in pairs], axis=2)
                static = np.asarray(ob.read @ beyond_basis(cs, basis, F.reshape(F.shape[0], -1))).reshape(
                    -1, lam.size, len(pairs))
            out.append(self._columns(ob, cs, BK, BM, static) * st.p[None, :])
        return np.vstack(out)


def _timed_modes(model, n_modes: int, K, M) -> tuple:
    """(the first ``n_modes`` modes of ``model`` with matrices K, M, the seconds the solve took): a
    job :meth:`ModalResidual._solved` may send to a spare process."""
    t = time.perf_counter()
    modes = solve_modes(model, n_modes=n_modes, K=K, M=M)
    return modes, time.perf_counter() - t


def beyond_basis(cs: ConfigState, basis, F) -> np.ndarray:
    """-(G - sum_basis phi_k phi_k^T / (lambda_k + mu)) F: the modes above the computed ones answer a
    force F quasi-statically (modal acceleration), G = (K + mu M)^-1 on the constrained DOFs, mu a
    small shift that keeps a free board's G finite. It completes the modal expansion of the
    eigenvector derivative (eqs. 3.8-3.14) for parameters that act over the whole board, and gives
    the static corrections of :mod:`.reanalysis`. The factorisation is kept with the state."""
    from ..fe.linsolve import factorize
    from ..fe.modal import reduced_system

    lam_b = np.r_[np.zeros(cs.modes.n_rigid), cs.modes.omega2]
    if cs.static is None:
        red, Kr, Mr = reduced_system(cs.model, cs.K, cs.M)
        mu = 1e-3 * lam_b[lam_b > 0].min()
        cs.static = (red, mu, factorize((Kr + mu * Mr).tocsc()))
    red, mu, f = cs.static
    G = red.expand(f.solve(red.T.T @ F))
    return -(G - basis @ ((basis.T @ F) / (lam_b + mu)[:, None]))
