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

    def values(self, p) -> dict:
        """{parameter name: value [SI]}."""
        return dict(zip(self.names, np.asarray(p, float).tolist()))


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
