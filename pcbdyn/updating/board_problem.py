"""Bridge from a board (board.toml) and its measured data to the plain-matrix updating driver.

A :class:`BoardProblem` holds the board and the names of the parameters being updated (its
``[[parameters]]``, or a subset). For each test configuration, :meth:`BoardProblem.system` builds a
:class:`BoardSystem`: the FE model of that configuration, its constraint reduction and the
callable ``model(p) -> (K, M, dKs, dMs)`` the driver needs, on the constrained (independent) DOFs.
:meth:`BoardProblem.configuration` turns measured data into a driver
:class:`~pcbdyn.updating.iteration.Configuration` with the measurement matrix P (model read at the
test points through the shell shape functions, reduced to the independent DOFs) and a pairing
adapter that skips the rigid-body modes of a free board.

Design variables are relative, x = dp/p (column weighting, thesis eq. 4.41); spring stiffnesses
(wedge-lock k_rot, standoff k), which span decades, are updated on a log scale
(:attr:`BoardProblem.log_scale`). Typical use::

    prob = BoardProblem(board, ["t_U1", "t_U2"])
    meas = MeasuredModes.from_test(read_uff("test.uff").modes)
    cfgs = prob.configuration(None, meas, "freq")                # frequencies, MAC pairing
    cfgs = prob.mode_configurations(None, meas, "qms")           # or: QMS, one block per mode
    res, before, after = run(prob, cfgs, solver="bounded", check=[prob.configuration(None, meas)])

Each Configuration carries its own pairing adapter (``cfg.pairing``) and rigid-mode count
(``cfg.n_rigid``); :func:`config_pairing` combines them into the one callable the driver's
``update``/``build_equations`` take. For shape methods (QMS, FBM) prefer
:meth:`BoardProblem.mode_configurations`: one configuration per measured mode on the model
dynamically condensed to the measured DOFs at that mode's frequency (no Guyan bias). Localisation
reuses the same configurations: ``build_equations(cfgs, prob.p0, config_pairing(cfgs))``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..board import build_model
from ..correlation.frf import fdac
from ..correlation.pairing import pair_modes
from ..fe.assembly import assemble
from ..fe.constraints import build_reduction
from ..fe.probe import model_probe
from .iteration import Configuration, build_equations, update
from .matching import transformation

#: target attributes that are spring stiffnesses: updated on a log scale
STIFFNESS_ATTRS = ("k_rot", "k")


def is_stiffness(param) -> bool:
    """True when every target of the parameter is a spring stiffness (``fixtures.<name>.k[_rot]``)."""
    return all(t.startswith("fixtures.") and t.rsplit(".", 1)[1] in STIFFNESS_ATTRS for t in param.targets)


@dataclass
class MeasuredModes:
    """Measured modes of one configuration in SI: frequencies [Hz]; optionally shapes
    (n_meas, n_modes) at points ``xyz`` (n_meas, 3) [m] along unit ``directions`` (n_meas, 3);
    ``mode_numbers``: 1-based elastic mode number of each frequency, used to pair by order when
    there are no shapes (default 1..n)."""

    frequencies: np.ndarray
    shapes: np.ndarray | None = None
    xyz: np.ndarray | None = None
    directions: np.ndarray | None = None
    mode_numbers: np.ndarray | None = None

    def __post_init__(self):
        self.frequencies = np.asarray(self.frequencies, float).ravel()
        if self.mode_numbers is None:
            self.mode_numbers = np.arange(1, self.frequencies.size + 1)
        self.mode_numbers = np.asarray(self.mode_numbers, int).ravel()
        if self.shapes is not None:
            self.shapes = np.asarray(self.shapes, float)
            if self.xyz is None or self.directions is None:
                raise ValueError("measured shapes need the points (xyz) and directions they were measured at")

    @classmethod
    def from_test(cls, test_modes, select=None) -> "MeasuredModes":
        """From :class:`pcbdyn.testdata.Modes` (e.g. ``read_uff(path).modes``); ``select``: 0-based
        test modes to keep."""
        idx = np.arange(test_modes.n_modes) if select is None else np.asarray(select, int)
        return cls(test_modes.frequencies[idx], test_modes.shapes[:, idx], test_modes.dof_xyz(),
                   test_modes.dofs.directions)


@dataclass
class MeasuredFRFs:
    """Measured receptances of one excitation in SI: ``frequencies`` [Hz] (n_f,), ``H`` (n_f, n_resp)
    [m/N] at points ``xyz`` (n_resp, 3) along unit ``directions`` (n_resp, 3), for a unit force at
    ``excite_xyz`` (3,) along ``excite_direction`` (3,)."""

    frequencies: np.ndarray
    H: np.ndarray
    xyz: np.ndarray
    directions: np.ndarray
    excite_xyz: np.ndarray
    excite_direction: np.ndarray

    @classmethod
    def from_test(cls, frfs) -> list:
        """One MeasuredFRFs per reference DOF of :class:`pcbdyn.testdata.FRFs` (any kind, converted to
        receptance); the 0 Hz line (no receptance from mobility or accelerance there) and responses
        with missing (NaN) FRFs are dropped."""
        rec = frfs.as_kind("receptance")
        pts = rec.points
        r_xyz = pts.xyz[pts.index(rec.response.point_ids)]
        e_xyz = pts.xyz[pts.index(rec.reference.point_ids)]
        f = np.asarray(rec.frequencies, float)
        lines = f > 0
        out = []
        for k in range(rec.H.shape[2]):
            H = rec.H[lines, :, k]
            ok = np.all(np.isfinite(H), axis=0)
            if not ok.any():
                continue
            out.append(cls(f[lines], H[:, ok], r_xyz[ok], rec.response.directions[ok],
                           e_xyz[k], rec.reference.directions[k]))
        if not out:
            raise ValueError("the FRFs hold no complete response column for any reference")
        return out


def resonance_lines(f, H) -> np.ndarray:
    """Frequencies [Hz] of the local maxima of sum_i |H_i|^2 over the lines (the resonances seen on the
    sampled FRFs, H (n_f, n_resp))."""
    s = np.sum(np.abs(H) ** 2, axis=1)
    k = np.flatnonzero((s[1:-1] > s[:-2]) & (s[1:-1] > s[2:])) + 1
    return np.asarray(f)[k]


def choose_frf_frequencies(f, H_x, H_a, gap: float = 0.1, n_max: int = 8, min_fdac: float = 0.9,
                           free: bool = False):
    """Automatic updating frequencies (thesis section 2.2.3): indices of lines of ``f`` [Hz].

    Rule: resonances are the peaks of the measured (``H_x``) and model (``H_a``) FRFs (both (n_f,
    n_resp)); a line qualifies when it lies more than ``gap`` (relative) from every resonance (the
    receptance there is not dominated by one mode and a frequency shift between model and test does
    not flip it) and its FDAC between test and model at that same line (eq. 2.6, diagonal) is at least
    ``min_fdac``. In each interval between consecutive resonances (and below the first, above the
    last) the qualifying line with the highest FDAC is taken; of these, the ``n_max`` with the highest
    FDAC are kept. A ``free`` structure has no lines below its first resonance: there the response
    is the rigid-body mass line, which no stiffness parameter moves. Returns (indices sorted by frequency, FDAC of every line, note or None); when no
    line reaches ``min_fdac`` the best-correlated lines are taken and the note says so.
    """
    f = np.asarray(f, float)
    res = np.unique(np.concatenate([resonance_lines(f, H_x), resonance_lines(f, H_a)]))
    cos = np.diagonal(fdac(H_x, H_a)[0]).copy()
    away = (f > (res[0] if free and res.size else 0.0)) & np.all(np.abs(f[:, None] / np.where(res > 0, res, np.inf)[None, :] - 1) > gap, axis=1)
    interval = np.searchsorted(res, f)
    note = None
    ok = away & (cos >= min_fdac)
    if not ok.any():
        ok = away
        note = (f"no line away from the resonances has FDAC >= {min_fdac}; the best-correlated ones are used "
                "(check the pairing of test and model, or give --frf-freqs)")
    if not ok.any():
        raise ValueError("no measured line lies away from the resonances; give the updating frequencies (--frf-freqs)")
    picks = [k[np.argmax(cos[k])] for i in np.unique(interval[ok]) for k in [np.flatnonzero(ok & (interval == i))]]
    picks = sorted(picks, key=lambda k: -cos[k])[:n_max]
    return np.sort(np.asarray(picks, int)), cos, note


class BoardSystem:
    """One configuration of the board as the driver sees it.

    ``model(p)`` returns (K, M, dKs, dMs) reduced to the independent DOFs (CSC), the derivatives
    from the elements each parameter touches (:meth:`pcbdyn.board.Parameter.derivatives`). The last
    evaluation is cached (the driver and its line search ask for the same p more than once).
    """

    def __init__(self, board, config, names, mesh_size=None):
        self.config = config
        self.bm = build_model(board, config, mesh_size)
        missing = [n for n in names if n not in self.bm.parameters]
        if missing:
            raise KeyError(f"parameters {missing} are not in [[parameters]] of {board.path.name}; "
                           f"known: {', '.join(self.bm.parameters) or 'none'}")
        self.names = list(names)
        K, M = assemble(self.bm.model)
        self.reduction = build_reduction(self.bm.model, K, M)
        self.n_rigid = 6 if self.bm.model.free else 0
        self._cache = (None, None)

    def model(self, p):
        """(K, M, dKs, dMs) at parameter values ``p`` [SI], on the independent DOFs."""
        p = np.asarray(p, float)
        if self._cache[0] is not None and np.array_equal(self._cache[0], p):
            return self._cache[1]
        bm = self.bm.with_parameters(dict(zip(self.names, p.tolist())))
        red = self.reduction.reduce
        K, M = assemble(bm.model)
        dKs, dMs = [], []
        for name in self.names:
            dK, dM = bm.parameters[name].derivatives(bm)
            dKs.append(red(dK))
            dMs.append(red(dM))
        out = (red(K), red(M), dKs, dMs)
        self._cache = (p.copy(), out)
        return out

    def board_model(self, p):
        """The board model (:class:`pcbdyn.board.model.BoardModel`) at parameter values ``p``."""
        return self.bm.with_parameters(dict(zip(self.names, np.asarray(p, float).tolist())))

    def measurement_matrix(self, xyz, directions) -> sp.csr_matrix:
        """P (n_meas, n_independent): the model read at the points along the directions."""
        P = model_probe(self.bm.model, xyz, directions).P
        return sp.csr_matrix(P @ self.reduction.T)

    def excitation_dof(self, xyz, direction):
        """(independent DOF index, note or None) of a unit force at point ``xyz`` along ``direction``.
        The FRF equations (3.34, 3.35, 3.40) take one excited DOF: a point on a node along an axis maps
        to it exactly; otherwise the DOF with the largest interpolation weight is used and the note
        says so (move the excitation onto a node, e.g. with a mesh size that divides its coordinates)."""
        row = self.measurement_matrix(np.asarray(xyz, float)[None], np.asarray(direction, float)[None]).toarray()[0]
        w = np.abs(row)
        if w.max() == 0:
            raise ValueError(f"excitation at {np.round(np.asarray(xyz) * 1e3, 2).tolist()} mm moves no free DOF")
        j = int(np.argmax(w))
        if np.isclose(row[j], 1.0) and np.sum(w > 1e-9) == 1:
            return j, None
        return j, (f"excitation at {np.round(np.asarray(xyz) * 1e3, 2).tolist()} mm is not on a node along an axis: "
                   "the nearest-weight DOF is excited instead (biased); put the excitation on a mesh node")

    def pairing(self, measured: MeasuredModes, min_mac: float = 0.5):
        """The driver's pairing callable: by MAC (:func:`pcbdyn.correlation.pairing.pair_modes`)
        when shapes are measured, else by elastic mode number; rigid-body modes never pair."""
        nr = self.n_rigid

        def by_mac(f_a, phi_a, f_x, phi_x):
            out = -np.ones(np.size(f_x), int)
            if phi_x is None:
                k = nr + measured.mode_numbers - 1
                ok = k < np.size(f_a)
                out[ok] = k[ok]
                return out
            res = pair_modes(np.asarray(phi_x), np.asarray(phi_a)[:, nr:], f_x, np.asarray(f_a)[nr:], min_mac=min_mac)
            for pr in res.pairs:
                out[pr.test] = pr.model + nr
            return out

        return by_mac


class DynamicReduced:
    """``model(p)`` of one measured mode: the board reduced onto the measured DOFs by the dynamic map
    at that mode's measured angular frequency ``omega`` (thesis ch. 2.2; P T = I, T frozen within an
    evaluation, so T^T dK T is the exact derivative of the condensed dynamic stiffness). At the test
    frequency the condensation is exact for the mode there, unlike Guyan's static one, so shape
    equations on it carry no reduction bias."""

    def __init__(self, system: BoardSystem, P, omega: float):
        self.system, self.P, self.omega = system, P, float(omega)

    def __call__(self, p):
        K, M, dKs, dMs = self.system.model(p)
        T = transformation(K, M, self.P, self.omega)

        def red(A):
            return np.asarray(T.T @ (A @ T))

        Kr, Mr = red(K), red(M)
        return 0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T), [red(d) for d in dKs], [red(d) for d in dMs]


class BoardProblem:
    """The board, the parameters being updated and their scaling (see the module docstring).

    ``names``: parameter names from the board's ``[[parameters]]`` (default: all of them).
    ``mesh_size`` [m] overrides the board's. Attributes: ``parameters`` (the
    :class:`pcbdyn.board.Parameter` objects, base configuration), ``p0`` (their board values, SI),
    ``bounds`` ((lower, upper) arrays), ``log_scale`` (indices of stiffness parameters),
    ``units`` (display units of board.toml).
    """

    def __init__(self, board, names=None, mesh_size=None):
        self.board = board
        self.mesh_size = mesh_size
        known = [p.name for p in board.parameters]
        if not known:
            raise ValueError(f"{board.path.name}: no [[parameters]] to update; add e.g. [[parameters]] name = \"t_U1\", "
                             "target = \"components.U1.thickness\", bounds = [\"2 mm\", \"10 mm\"]")
        self.names = list(names) if names else known
        bad = [n for n in self.names if n not in known]
        if bad:
            raise ValueError(f"--params: {bad} are not parameters of {board.path.name} (known: {', '.join(known)})")
        self.systems: dict = {}
        base = self.system(None)
        self.parameters = [base.bm.parameters[n] for n in self.names]
        self.p0 = np.array([p.value for p in self.parameters], float)
        self.bounds = (np.array([p.bounds[0] for p in self.parameters]), np.array([p.bounds[1] for p in self.parameters]))
        self.log_scale = [i for i, p in enumerate(self.parameters) if is_stiffness(p)]
        self.units = [p.unit for p in self.parameters]
        bad0 = [p.name for p in self.parameters if p.value == 0]
        if bad0:
            raise ValueError(f"parameters {bad0} start at zero; relative updating (x = dp/p, thesis eq. 4.41) needs "
                             "a non-zero starting value in board.toml")

    def system(self, config) -> BoardSystem:
        """The (cached) :class:`BoardSystem` of a configuration name (None: the base one)."""
        if config not in self.systems:
            self.systems[config] = BoardSystem(self.board, config, self.names, self.mesh_size)
        return self.systems[config]

    def configuration(self, config, measured: MeasuredModes, method: str = "freq", n_modes=None,
                      min_mac: float = 0.5, **options) -> Configuration:
        """A driver Configuration for configuration ``config`` with its measured modes.

        Shapes (``measured.shapes``) give P and MAC pairing; frequencies only pair by mode number.
        ``n_modes`` analytical modes are solved per iteration (default: rigid-body modes + the
        highest measured mode number + 4). ``options`` go to Configuration (matching, sigma, ...).
        """
        sysm = self.system(config)
        P = None if measured.shapes is None else sysm.measurement_matrix(measured.xyz, measured.directions)
        n = n_modes or sysm.n_rigid + int(max(measured.mode_numbers.max(), measured.frequencies.size)) + 4
        cfg = Configuration(model=sysm.model, f_x=measured.frequencies, phi_x=measured.shapes, P=P, method=method,
                            n_modes=n, name=config or "base", **options)
        cfg.pairing = sysm.pairing(measured, min_mac)
        cfg.n_rigid = sysm.n_rigid
        return cfg

    def mode_configurations(self, config, measured: MeasuredModes, method: str = "qms", min_mac: float = 0.5,
                            **options) -> list:
        """One driver Configuration per measured mode, each on the board dynamically reduced onto the
        measured DOFs at that mode's frequency (:class:`DynamicReduced`), for the shape methods
        ("qms", "fbm"). Pairing in the reduced space by MAC; every reduced mode is solved (the
        reduced systems are small)."""
        if measured.shapes is None:
            raise ValueError(f"configuration {config or 'base'!r}: {method} needs measured shapes")
        sysm = self.system(config)
        P = sysm.measurement_matrix(measured.xyz, measured.directions)
        out = []
        for k, f in enumerate(measured.frequencies):
            one = MeasuredModes(measured.frequencies[k:k + 1], measured.shapes[:, k:k + 1], measured.xyz,
                                measured.directions)
            cfg = Configuration(model=DynamicReduced(sysm, P, 2 * np.pi * f), f_x=one.frequencies, phi_x=one.shapes,
                                method=method, n_modes=P.shape[0], name=f"{config or 'base'}:{k + 1}", **options)
            cfg.n_rigid = 0
            cfg.pairing = _mac_pairing(min_mac)
            out.append(cfg)
        return out

    def frf_configurations(self, config, measured: list, method: str = "frf-out", freqs=None,
                           damping: str = "undamped", n_max: int = 8, **options) -> tuple:
        """Driver Configurations (one per excitation in ``measured``, a list of :class:`MeasuredFRFs`)
        for the FRF methods "frf-in" (eq. 3.34), "frf-out" (indirect eq. 3.35) or "frf-direct"
        (eq. 3.40), and notes for the user.

        ``freqs`` [Hz]: updating frequencies (the nearest measured line of each is used); None picks
        them with :func:`choose_frf_frequencies` against the model's FRFs at the initial parameters.
        ``damping``: treatment of the unknown damping in the data (appendix A; see
        :class:`~pcbdyn.updating.iteration.Configuration`). The measured responses are expanded to
        the model DOFs at each iteration (matching "expand")."""
        if not method.startswith("frf"):
            raise ValueError(f"method={method!r}: frf_configurations builds 'frf-in', 'frf-out' or 'frf-direct'")
        sysm = self.system(config)
        cfgs, notes = [], []
        for k, m in enumerate(measured):
            P = sysm.measurement_matrix(m.xyz, m.directions)
            j, note = sysm.excitation_dof(m.excite_xyz, m.excite_direction)
            notes += [note] if note else []
            f = np.asarray(m.frequencies, float)
            if freqs is None:
                K, M, _, _ = sysm.model(self.p0)
                H_a = model_receptance(K, M, P, j, 2 * np.pi * f)
                idx, _, note = choose_frf_frequencies(f, m.H, H_a, n_max=n_max, free=sysm.n_rigid > 0)
                notes += [note] if note else []
            else:
                want = np.atleast_1d(np.asarray(freqs, float))
                if want.min() < f.min() or want.max() > f.max():
                    raise ValueError(f"--frf-freqs: {want.tolist()} Hz must lie within the measured lines "
                                     f"{f.min():g}-{f.max():g} Hz")
                idx = np.unique(np.argmin(np.abs(f[:, None] - want[None, :]), axis=0))
            H = m.H[idx].T
            if np.iscomplexobj(H) and not np.any(H.imag) and damping == "undamped":
                H = H.real
            name = f"{config or 'base'}:frf{k + 1}"
            cfg = Configuration(model=sysm.model, P=P, frf_omegas=2 * np.pi * f[idx], H_x=H, excitation=j,
                                method=method, damping=damping, name=name, **options)
            cfg.n_rigid = sysm.n_rigid
            cfg.pairing = sysm.pairing(MeasuredModes(np.zeros(0)))
            cfg.frf_hz = f[idx]
            cfgs.append(cfg)
        return cfgs, notes

    def values(self, p) -> dict:
        """{parameter name: value [SI]}."""
        return dict(zip(self.names, np.asarray(p, float).tolist()))


def model_receptance(K, M, P, j: int, omegas) -> np.ndarray:
    """Undamped model receptances (n_w, n_meas) P H(w) e_j at ``omegas`` [rad/s] by modal
    superposition (eq. 3.29 with no damping) of every mode up to three times the highest frequency,
    rigid-body modes included: accurate enough to find resonances and correlated lines, and one
    eigensolution instead of a factorisation per line."""
    from ..fe.modal import eigenpairs

    w = np.asarray(omegas, float)
    lam, Phi, _ = eigenpairs(K, M, f_max=3 * w.max() / (2 * np.pi), free=True)
    with np.errstate(divide="ignore"):
        terms = (P @ Phi) * Phi[j]
        return np.real_if_close(terms @ (1.0 / (lam[:, None] - w[None, :] ** 2))).T


def _mac_pairing(min_mac):
    def pairing(f_a, phi_a, f_x, phi_x):
        out = -np.ones(np.size(f_x), int)
        for pr in pair_modes(np.asarray(phi_x), np.asarray(phi_a), f_x, f_a, min_mac=min_mac).pairs:
            out[pr.test] = pr.model
        return out

    return pairing


def config_pairing(configs):
    """One pairing callable for the driver that dispatches to each configuration's own adapter.

    The driver calls ``pairing(f_a, phi_a, f_x, phi_x)`` configuration by configuration, in order,
    once per state; configurations are identified by their measured frequency array."""
    table = [(np.asarray(c.f_x), c.pairing) for c in configs]

    def pairing(f_a, phi_a, f_x, phi_x):
        fx = np.asarray(f_x)
        for f, fn in table:
            if f.shape == fx.shape and np.array_equal(f, fx):
                return fn(f_a, phi_a, f_x, phi_x)
        raise ValueError("measured frequencies of no known configuration")

    return pairing


def correlation_state(configs, p):
    """Per configuration at ``p``: the pairs (as in ``pcbdyn correlate``: test_mode, model_mode
    (1-based, elastic modes), f_test_hz, f_model_hz, df_pct, mac) and the max |df| in percent."""
    _, _, states = build_equations(configs, p, config_pairing(configs))
    out = []
    for cfg, st in zip(configs, states):
        pairs = []
        for k, (u, fa) in enumerate(zip(st["used"], st["f_a"])):
            ft = float(cfg.f_x[u])
            pairs.append({"test_mode": int(u) + 1, "model_mode": int(st["pairs"][u]) + 1 - cfg.n_rigid,
                          "f_test_hz": ft, "f_model_hz": float(fa), "df_pct": 100.0 * (float(fa) - ft) / ft,
                          "mac": None if st.get("mac") is None else float(st["mac"][k])})
        out.append({"configuration": cfg.name, "pairs": pairs,
                    "max_freq_error_pct": max(abs(q["df_pct"]) for q in pairs)})
    return out


def run(problem: BoardProblem, configs, solver: str = "ls", check=None, **kwargs):
    """Update ``problem``'s parameters against ``configs`` (bounds, log scale and per-configuration
    pairing filled in); returns (UpdateResult, before, after), before/after from
    :func:`correlation_state` on ``check`` (default ``configs``; give the full-model configurations
    from :meth:`BoardProblem.configuration` when updating on :meth:`BoardProblem.mode_configurations`)."""
    check = configs if check is None else check
    before = correlation_state(check, problem.p0)
    res = update(configs, problem.p0, solver=solver, bounds=problem.bounds, log_scale=problem.log_scale,
                 pairing=config_pairing(configs), **kwargs)
    after = correlation_state(check, res.p)
    return res, before, after
