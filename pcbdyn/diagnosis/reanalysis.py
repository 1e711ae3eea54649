"""Eigen-solutions near a solved state without re-solving: Rayleigh-Ritz on the state's modes and
their static corrections (the combined approximations of structural reanalysis).

Ranking a shortlist of candidate effects fits each with the declared parameters and the effects
already chosen, a few Gauss-Newton steps apiece: a hundred full re-solves per search step. Every
one of those fits starts from the same solved state (K, M, its modes Phi with eigenvalues Lambda)
and moves a handful of directions d (each candidate's magnitude, the parameters), along which K and
M change by dK_d, dM_d. The modes of K + sum a_d dK_d, M + sum a_d dM_d lie close to the span of

    Phi  and  X_d = (K + mu M)^-1 (dK_d - dM_d Lambda) Phi   less its part along Phi

(the first term of their change, thesis eqs. 3.8-3.14, with every mode above the computed ones
answering quasi-statically: :func:`.residual.beyond_basis`). A point mass or a spring acts on a few
DOFs, so its X_d has a rank of 1-3; the columns are compressed to their numerical rank. On that
basis B the pencil is (B^T K B + sum a_d B^T dK_d B, ...), a few tens of rows: one small dense
eigen-problem per trial instead of a sparse solve, the shapes at the points read as (read B) y and
the sensitivities taken in B (phi_k^T dK phi_i = y_k^T B^T dK B y_i). A ranking fit needs its
chi^2 to a fraction of the noise, not exactly: the fits that win are then re-fitted with full
re-solves (:func:`.select.search`), which decide.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import scipy.linalg as sla

from .residual import ConfigState, State, beyond_basis, paired_state

#: static-correction directions are compressed to the columns whose M-norm share exceeds this
RANK_TOL = 1e-8
#: a load's singular values below this share of its largest are dropped before its static solves
COLUMN_TOL = 1e-12
#: static corrections are solved for this many directions at a time (:meth:`_Config.corrections`)
SOLVE_BLOCK = 32
#: eigenvalues below this share of the state's first elastic one are rigid-body modes
RIGID_SHARE = 1e-6


class _BasisModes:
    """The part of :class:`pcbdyn.fe.modal.Modes` a paired state and its sensitivities read, in
    the coefficients of a reduced basis: ``frequencies`` [Hz], ``n_rigid``, ``omega2``, ``coef``
    (n_basis, n_rigid + n_elastic) of [rigid, elastic]."""

    def __init__(self, lam, coef, n_rigid):
        self.n_rigid, self.coef = n_rigid, coef
        self.omega2 = lam[n_rigid:]
        self.frequencies = np.sqrt(np.maximum(self.omega2, 0.0)) / (2.0 * np.pi)


def _column_space(F) -> np.ndarray:
    """``F``'s columns reduced to an orthogonal basis of their span, scaled by the singular values
    (F = result V^T with orthonormal V^T rows): a local direction (a point's mass or spring) loads a
    few DOFs, so its many paired modes' loads have a rank of 1-3, and the static solves that
    follow are as many. Spans and the M-norms a compression reads are kept."""
    rows = np.flatnonzero(np.any(F != 0.0, axis=1))
    if rows.size == 0 or rows.size >= F.shape[1]:
        return F
    U, s, _ = np.linalg.svd(F[rows], full_matrices=False)
    keep = s > COLUMN_TOL * s[0]
    out = np.zeros((F.shape[0], int(keep.sum())))
    out[rows] = U[:, keep] * s[keep]
    return out


class _Config:
    """One configuration's reanalysis: the state's modes, directions' static corrections (compressed)
    and the products a basis of them needs, each made once."""

    def __init__(self, ob, cs: ConfigState, n_modes: int):
        self.ob, self.cs, self.n_modes = ob, cs, n_modes
        self.phi = np.column_stack([cs.modes.rigid_shapes, cs.modes.shapes])
        self.lam = np.r_[np.zeros(cs.modes.n_rigid), cs.modes.omega2]
        self.paired = cs.modes.shapes[:, cs.pairs]
        self.lam_p = cs.modes.omega2[cs.pairs]
        self.read_phi = None if ob.shapes is None else np.asarray(ob.read @ self.phi)
        self.M_phi = cs.M @ self.phi
        self.X, self.read_X = {}, {}
        self._local: dict = {}
        self._grams: dict = {}

    def corrections(self, loads) -> None:
        """The compressed static corrections of the directions ``loads`` = [(key, dK, dM)] not yet made, kept:
        their static solves in blocks of :data:`SOLVE_BLOCK` directions (a block of right-hand sides reads the
        factor once: a screen of many candidates costs a few solves, not one each)."""
        items = list({key: (dK, dM) for key, dK, dM in loads if key not in self.X}.items())
        for at in range(0, len(items), SOLVE_BLOCK):
            chunk = items[at:at + SOLVE_BLOCK]
            F = [_column_space(dK @ self.paired - (dM @ self.paired) * self.lam_p[None, :]) for _, (dK, dM) in chunk]
            F_all = np.hstack(F)
            X_all = beyond_basis(self.cs, self.phi, F_all) if F_all.shape[1] else F_all
            MX_all = self.cs.M @ X_all
            ends = np.cumsum([0] + [f.shape[1] for f in F])
            for (key, _), a, b in zip(chunk, ends[:-1], ends[1:]):
                self._keep(key, X_all[:, a:b], MX_all[:, a:b])

    def _keep(self, key, X, MX) -> None:
        """Direction ``key``'s correction X (and M X) made M-orthogonal to the modes and compressed to its rank."""
        along = self.phi.T @ MX
        X = X - self.phi @ along  # M-orthogonal to the modes (to round-off already)
        MX = MX - self.M_phi @ along
        d, U = np.linalg.eigh(X.T @ MX)
        keep = d > RANK_TOL * max(d.max(initial=0.0), 1e-300)
        W = U[:, keep] / np.sqrt(d[keep])
        X = X @ W
        self.X[key] = X
        self.read_X[key] = None if self.read_phi is None else np.asarray(self.ob.read @ X)

    def moved(self, key, dK, dM, keys) -> tuple:
        """(B^T dK B, B^T dM B) of direction ``key`` on the basis [phi, X_k for k in ``keys``], from
        the rows the direction touches (a candidate's dK and dM are local), cut out once; each basis's
        :class:`_Moves` keeps what this returns."""
        if key not in self._local:
            coo = [D.tocoo() for D in (dK, dM)]
            rows, cols = (np.union1d(*(getattr(D, ax) for D in coo)) for ax in ("row", "col"))
            self._local[key] = rows, cols, [D.tocsr()[rows][:, cols] for D in (dK, dM)]
        rows, cols, local = self._local[key]
        B_rows, B_cols = (np.column_stack([self.phi[at]] + [self.X[k][at] for k in keys]) for at in (rows, cols))
        return tuple(B_rows.T @ (D @ B_cols) for D in local)

    def moved_parameter(self, j: int, dK, dM, keys) -> tuple:
        """:meth:`moved` of the declared parameter ``j``, whose dK and dM span the structure (:meth:`_gram`)."""
        blocks = [None] + list(keys)
        return tuple(self._gram(D, ("p", j, t), blocks) for t, D in enumerate((dK, dM)))

    def _gram(self, D, name, blocks) -> np.ndarray:
        """B^T D B on the basis of ``blocks`` (None: the modes; else a direction's key) for the symmetric
        structure-wide matrix ``D`` called ``name`` (the stiffness, the mass, a declared parameter's derivative):
        each block pair made once and read transposed the other way round, so that a screen's bases, which share
        the modes and the chosen effects, pay one product with D for each trial's new direction."""
        def made(a, b):
            return (name, a, b) in self._grams or (name, b, a) in self._grams

        while True:
            missing = {b: [a for a in blocks if not made(a, b)] for b in blocks}
            b = max(blocks, key=lambda b: len(missing[b]))
            if not missing[b]:
                break
            D_b = D @ self._block(b)
            for a in missing[b]:
                self._grams[(name, a, b)] = self._block(a).T @ D_b
        return np.block([[self._grams[(name, a, b)] if (name, a, b) in self._grams else self._grams[(name, b, a)].T
                          for b in blocks] for a in blocks])

    def _block(self, a) -> np.ndarray:
        return self.phi if a is None else self.X[a]

    def basis(self, keys) -> tuple:
        """(K_B, M_B, T, points): the state's pencil on [phi, X_k], the M-orthonormal change of
        basis T that drops dependent columns, and the basis at the points (None without shapes)."""
        blocks = [None] + list(keys)
        KB, MB = (self._gram(D, name, blocks) for D, name in ((self.cs.K, "K"), (self.cs.M, "M")))
        KB, MB = 0.5 * (KB + KB.T), 0.5 * (MB + MB.T)
        d, U = np.linalg.eigh(MB)
        keep = d > 1e-10 * d.max()
        T = U[:, keep] / np.sqrt(d[keep])
        points = None if self.read_phi is None else np.column_stack([self.read_phi] + [self.read_X[k] for k in keys])
        return KB, MB, T, points


class _Moves:
    """The reduced pencil's change along each direction of a fit, each made when first asked for: a
    screen at the state's own parameters and effects (:func:`.scan.saturated`) moves one direction."""

    def __init__(self, makers: list):
        self._makers, self._made = makers, {}

    def __getitem__(self, i: int) -> tuple:
        if i not in self._made:
            self._made[i] = self._makers[i]()
        return self._made[i]


class Reanalysis:
    """Reduced evaluations of the residual ``res`` near its solved state ``st`` (module doc).
    ``evaluate(p, candidates, values)`` and ``effect_columns(state, candidates)`` stand in for the
    residual's own, for states reached from ``st`` by moving the declared parameters and the
    candidates' magnitudes."""

    def __init__(self, res, st: State):
        self.res, self.st = res, st
        self.base = {c.name: v for c, v in zip(st.candidates, st.values)}
        self.configs = [_Config(ob, cs, res.n_modes(ob)) for ob, cs in zip(res.observations, st.configs)]
        models = [cs.model for cs in st.configs]
        self.param_derivs = res.derivatives(st.p, models) if res.n_params else [[] for _ in models]
        self._bases: dict = {}

    def _derivative(self, k: int, c):
        """(dK, dM) of candidate ``c`` in configuration k at the state's parameters (kept by the residual's
        :class:`.combined.Effects`)."""
        return self.res.effects.derivative(k, self.st.configs[k].model, c, self.st.p)

    def _moved_effect(self, k: int, c, names) -> tuple:
        return self.configs[k].moved(c.name, *self._derivative(k, c), names)

    def _directions(self, candidates) -> list:
        """The candidates a fit moves: its own, then the solved state's effects it leaves out
        (they go back to zero)."""
        names = {c.name for c in candidates}
        return list(candidates) + [c for c in self.st.candidates if c.name not in names]

    def _basis(self, k: int, candidates) -> tuple:
        """Configuration k's reduced pencil for a fit of ``candidates`` (with every parameter)."""
        dirs = self._directions(candidates)
        key = (k, tuple(c.name for c in dirs))
        if key not in self._bases:
            cfg = self.configs[k]
            cfg.corrections([(c.name, *self._derivative(k, c)) for c in dirs])
            names = [c.name for c in dirs]
            KB, MB, T, points = cfg.basis(names)
            params = [partial(cfg.moved_parameter, j, dK, dM, names) for j, (dK, dM) in enumerate(self.param_derivs[k])]
            effects = [partial(self._moved_effect, k, c, names) for c in dirs]
            self._bases[key] = (KB, MB, T, points, _Moves(params + effects))
        return self._bases[key]

    def prepare(self, candidates) -> None:
        """The static corrections of ``candidates`` made together before a screen evaluates them one by one
        (:meth:`_Config.corrections`)."""
        for k, cfg in enumerate(self.configs):
            loads = []
            for c in candidates:
                try:
                    loads.append((c.name, *self._derivative(k, c)))
                except ValueError:  # not on this state's mesh: its evaluations fail as they would alone
                    continue
            cfg.corrections(loads)

    def evaluate(self, p, candidates=(), values=()) -> State:
        """The state at parameters ``p`` [SI] with ``candidates`` at ``values`` (the solved state's
        effects not among them at zero), from the reduced pencils; first order in the parameters."""
        p = np.asarray(p, float)
        st = State(p, list(candidates), np.asarray(values, float))
        dirs = self._directions(candidates)
        to = dict(zip((c.name for c in candidates), st.values))
        steps = np.r_[p - self.st.p, [to.get(c.name, 0.0) - self.base.get(c.name, 0.0) for c in dirs]]
        for k, cfg in enumerate(self.configs):
            KB, MB, T, points, moves = self._basis(k, candidates)
            moving = [(a, moves[i]) for i, a in enumerate(steps) if a != 0.0]
            K = KB + sum(a * GK for a, (GK, _) in moving)
            M = MB + sum(a * GM for a, (_, GM) in moving)
            lam, Z = sla.eigh(T.T @ K @ T, T.T @ M @ T)
            coef = T @ Z
            first = cfg.lam[cfg.cs.modes.n_rigid] if cfg.lam.size > cfg.cs.modes.n_rigid else 1.0
            nr = int(np.count_nonzero(lam < RIGID_SHARE * first))
            keep = np.r_[np.arange(nr), nr + np.arange(min(cfg.n_modes, lam.size - nr))]
            modes = _BasisModes(lam[keep], coef[:, keep], nr)
            at_points = None if points is None else points @ modes.coef
            U = None if at_points is None else at_points[:, nr:]
            st.configs.append(paired_state(cfg.ob, cfg.cs.model, None, None, modes, U, at_points))
        return st

    def effect_columns(self, st: State, candidates) -> np.ndarray:
        """(n_rows, n_candidates) of a reduced state (the candidates among its fit's)."""
        names = [c.name for c in self._directions(st.candidates)]
        out = []
        for k, (ob, cs) in enumerate(zip(self.res.observations, st.configs)):
            moves = self._basis(k, st.candidates)[4]
            n_par = len(self.param_derivs[k])
            C = cs.modes.coef
            paired = C[:, cs.modes.n_rigid + cs.pairs]
            BK = np.stack([C.T @ moves[n_par + names.index(c.name)][0] @ paired for c in candidates])
            BM = np.stack([C.T @ moves[n_par + names.index(c.name)][1] @ paired for c in candidates])
            out.append(self.res._columns(ob, cs, BK, BM))
        return np.vstack(out)
