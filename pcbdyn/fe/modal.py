"""Real normal modes of undamped models: K phi = omega^2 M phi, mass-normalised (phi^T M phi = 1).

Large systems: ARPACK (eigsh) in shift-invert mode about a small negative shift sigma, with
(K - sigma M)^-1 applied by a CHOLMOD factorisation (:mod:`.linsolve`). The shift makes the
operator positive definite even for a free model, and is kept far below the first elastic
eigenvalue so that the wanted eigenvalues stay well separated after inversion. Small systems
(or requests for most of the spectrum) use dense LAPACK. Uncoupled DOF groups (a flat plate's
bending and membrane DOFs) are solved apart (:mod:`.blocks`); when the wanted part of the
spectrum is bounded (``f_max``, or the modes already found in another group), a Sturm count (the
negative pivots of an LDL^T of K - lambda_cut M) tells eigsh exactly how many modes to find.

Rigid-body modes are recognised per mode, independently of units and mesh size: a mass-normalised
mode is rigid when its strain energy lambda = phi^T K phi is below ``RIGID_RTOL`` times its gross
energy |phi|^T |K| |phi|. For an exact rigid motion the element forces cancel to round-off
(ratio ~1e-17..1e-16); for an elastic mode the ratio falls with (element size / wavelength)^4 and
with the thinness of shells, but stays far above the threshold (measured on free square plates:
5.7e-8 for 128 x 128 quads at a/t = 100, 2.3e-9 for 64 x 64 at a/t = 1000).

Reusing the factorisation: ``solve_modes(..., keep_factor=True)`` returns ``Modes.shifted``, a
:class:`~.blocks.ShiftedInverse` whose ``solve(b)`` applies (K_r - S)^-1 to loads b on the
constrained DOFs (``Modes.reduction.T.T @ f`` for full-length loads f) with the factorisations the
eigen-solution made: static flexibility, modal acceleration and FRF residuals then need no
factorisation of their own. Without it the factors are freed with the solution. Independently,
every factorisation of a pattern seen before reuses its symbolic analysis (:mod:`.linsolve`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import lanczos
from .assembly import assemble
from .blocks import DENSE_MAX, ShiftedInverse, layout, uncoupled_blocks
from .constraints import Reduction, build_reduction
from .linsolve import (
    SingularMatrixError,
    factorize,
    has_no_negative_eigenvalue,
    negative_eigenvalue_count,
)
from .mesh import DOF_NAMES, NDOF
from .model import ModelError
from .threads import limited

__all__ = ["DENSE_MAX", "Modes", "eigenpairs", "reduce_matrix", "reduced_system", "solve_modes", "uncoupled_blocks"]

#: strain energy / gross energy below which a mode counts as a rigid-body (zero-frequency) mode
RIGID_RTOL = 1e-12
#: relative margin above a cut eigenvalue for the Sturm count, so that round-off in the LDL^T
#: pivots cannot drop a mode lying on the cut (the final selection is exact)
STURM_MARGIN = 1e-6
#: The relative residual tolerance on the shift-inverted Ritz pairs (block Lanczos and ARPACK).
#: The eigenvalues are taken as Rayleigh quotients, accurate to about its square (round-off), and
#: the shapes to about tol / relative gap: 1e-8 against 1e-10 saved 2 of 21 block steps on the
#: 112k-DOF plate with frequencies equal to 2e-12, and ~10 % of the diagnosis's coarse solves.
#: ARPACK's default ncv = max(2k+1, 20) is kept: more Lanczos vectors cost more solves than they
#: save on plates (measured at 60k DOF, k = 20).
EIGSH_TOL = 1e-8
#: groups from this size up are solved by block Lanczos (:mod:`.lanczos`) instead of ARPACK, with
#: blocks of this many vectors and at most max(6 k, LANCZOS_BASIS) basis vectors (and never more
#: than a quarter of the group). CPU against ARPACK, 20 modes: 11k DOF 0.09 s vs 0.12 s, 55k
#: 0.69 vs 0.93, 1M tilted 24 vs ~45; the six-part card's 2.9k-DOF groups ~10 % less per solve;
#: below ~1k DOF they cost the same. Blocks of 4 took the least CPU at 55k and 1M (1M: 8 took
#: 27 s, 12 took 30 s).
LANCZOS_MIN = 2000
LANCZOS_BLOCK = 4
LANCZOS_BASIS = 160


@dataclass
class Modes:
    """Elastic modes (frequencies in Hz, full-length mass-normalised shapes as columns) and the
    rigid-body modes found in a free model (full-length, mass-normalised); ``shifted``: the
    eigen-solution's factorisations, when asked for (see the module doc)."""

    frequencies: np.ndarray
    shapes: np.ndarray
    rigid_shapes: np.ndarray
    reduction: Reduction
    shifted: ShiftedInverse | None = None

    @property
    def n_rigid(self) -> int:
        return self.rigid_shapes.shape[1]

    @property
    def omega2(self) -> np.ndarray:
        """Elastic eigenvalues omega^2 [rad^2/s^2]."""
        return (2.0 * np.pi * self.frequencies) ** 2


def reduced_system(model, K=None, M=None):
    """(reduction, Kr, Mr): the constrained matrices as CSR.

    When the model has no multi-point constraints, the reduction only drops DOFs, and
    :meth:`Reduction.reduce` takes the reduced matrices by row/column selection instead of the
    triple product T^T A T.
    """
    if K is None or M is None:
        K, M = assemble(model)
    red = build_reduction(model, K, M)
    return red, reduce_matrix(red, K), reduce_matrix(red, M)


def reduce_matrix(red: Reduction, A) -> sp.csr_matrix:
    """T^T A T (see :meth:`Reduction.reduce`: by selection when there are no MPCs)."""
    return red.reduce(A)


def _mass_normalise(vec, Mr):
    mm = np.einsum("ij,ij->j", vec, Mr @ vec)
    return vec / np.sqrt(mm)


def _dense_eigs(Kr, Mr, shift):
    """All finite eigenpairs of the pencil, via M x = mu (K + shift M) x with mu = 1/(lambda + shift).

    This form needs only K + shift M positive definite, so it also takes a singular M (massless
    DOFs give mu = 0, i.e. infinite eigenvalues, which are dropped).
    """
    Kd = Kr.toarray()
    Md = Mr.toarray()
    try:
        mu, vec = sla.eigh(Md, Kd + shift * Md)
    except np.linalg.LinAlgError as exc:
        raise SingularMatrixError("K + shift M is not positive definite") from exc
    finite = mu > 1e-10 * mu.max()
    return vec[:, finite][:, ::-1]


class _Block:
    """One uncoupled DOF group: its matrices, its shift-invert factorisation (made once, reused
    when more modes are asked) and the eigenpairs found so far."""

    def __init__(self, idx, Kb, Mb, lower_plan):
        self.idx, self.K, self.M = idx, Kb, Mb  # CSR: faster products
        self._lower_plan = lower_plan  # () -> the gather plan of the lower triangle
        dk, dm = Kb.diagonal(), Mb.diagonal()
        both = (dk > 0) & (dm > 0)
        self.scale = float(np.median(dk[both] / dm[both])) if both.any() else 1.0
        self.sigma = -1e-9 * self.scale
        self.dense = Kb.shape[0] <= DENSE_MAX
        self._solver = None
        self._lower = None

    def shifted(self, s: float) -> sp.csc_matrix:
        """The lower triangle of K - s M (CSC), on the pattern of K and M."""
        if self._lower is None:
            plan = self._lower_plan()
            self._lower = (plan, self.K.data[plan.mask], self.M.data[plan.mask])
        plan, Kl, Ml = self._lower
        return plan.matrix(Kl - s * Ml)

    def solver(self):
        if self._solver is None:
            try:
                self._solver = factorize(self.shifted(self.sigma), lower=True)
            except SingularMatrixError as exc:
                raise ModelError(
                    "K + s M is singular for s > 0: some DOFs carry neither stiffness nor mass in "
                    "some direction (a massless mechanism); add supports or springs there"
                ) from exc
        return self._solver

    def first_eigenvalue(self, n_skip: int) -> float:
        """A cheap upper estimate of the block's first eigenvalue after ``n_skip`` (rigid) ones:
        three block inverse iterations and a Rayleigh-Ritz step. Orders the blocks of the first
        solve of a pattern."""
        if self.dense:
            return -np.inf
        X = np.random.default_rng(0).standard_normal((self.K.shape[0], n_skip + 4))
        for _ in range(3):
            X, _ = np.linalg.qr(self.solver().solve(self.M @ X))
        try:
            theta = sla.eigh(X.T @ (self.K @ X), X.T @ (self.M @ X), eigvals_only=True)
        except np.linalg.LinAlgError:
            return self.scale
        return float(theta[n_skip])

    def count_below(self, lam: float, rigid_expected: bool) -> int:
        """How many eigenvalues of the block lie below ``lam`` (Sturm count, rigid ones included).

        Without rigid modes expected the count is often 0, which one Cholesky of K - lam M proves
        (about three times faster than the LDL^T count); a block of a free model always holds
        some, so it goes to the LDL^T count at once.
        """
        A = self.shifted(lam)
        if not rigid_expected and has_no_negative_eigenvalue(A, lower=True):
            return 0
        return negative_eigenvalue_count(A, lower=True)

    def _solve(self, want: int):
        """The lowest ``want`` eigenpairs (all of them on the dense path), mass-normalised, with
        the rigid-body flags: (lam, vec, rigid, exhausted)."""
        n = self.K.shape[0]
        if self.dense or want >= n // 2:
            if n > 8 * DENSE_MAX:
                raise ModelError(
                    f"{want} modes asked of a {n}-DOF model: that is most of its spectrum; "
                    "ask for fewer modes or a lower f_max"
                )
            try:
                vec = _dense_eigs(self.K, self.M, self.scale)
            except SingularMatrixError:
                self.solver()  # raises the explanatory ModelError
                raise
            exhausted = True
        else:
            basis = max(6 * want, LANCZOS_BASIS)
            vec = self._block_lanczos(want, basis) if n >= LANCZOS_MIN and basis <= n // 4 else None
            if vec is None:
                op = self.solver().operator()
                v0 = np.random.default_rng(0).standard_normal(n)  # repeatable runs
                _, vec = spla.eigsh(
                    self.K, k=want, M=self.M, sigma=self.sigma, which="LM", OPinv=op, tol=EIGSH_TOL, v0=v0
                )
            exhausted = False
        vec = _mass_normalise(vec, self.M)
        lam = np.einsum("ij,ij->j", vec, self.K @ vec)
        absK = sp.csr_matrix((np.abs(self.K.data), self.K.indices, self.K.indptr), shape=self.K.shape)
        gross = np.einsum("ij,ij->j", np.abs(vec), absK @ np.abs(vec))
        return lam, vec, np.abs(lam) <= RIGID_RTOL * gross, exhausted

    def _block_lanczos(self, want: int, basis: int):
        """The lowest ``want`` eigenvectors by block Lanczos on L^-1 P M P^T L^-T, or None (not
        a Cholesky factor, or no convergence within ``basis`` vectors: ARPACK then)."""
        f = self.solver()
        if f.method != "cholmod":
            return None
        out = lanczos.largest(lambda Y: f.forward(self.M @ f.backward(Y)), self.K.shape[0], want,
                              LANCZOS_BLOCK, EIGSH_TOL, basis)
        return None if out is None else f.backward(out[1])

    def modes(self, want: int, n_needed: int | None):
        """Mass-normalised eigenpairs from the lowest up, until ``n_needed`` elastic modes are
        found or the block has no more: (lam, vec, rigid). The request grows (doubling, on the
        same factorisation) only when rigid-body modes took some of the first ``want``."""
        while True:
            lam, vec, rigid, exhausted = self._solve(want)
            if exhausted or n_needed is None or np.count_nonzero(~rigid) >= n_needed:
                return lam, vec, rigid
            want = max(2 * want, 6)

    def modes_below(self, lam_cut: float, cap: int | None, rigid_expected: bool):
        """Every eigenpair below ``lam_cut`` (at most the lowest ``cap``): (lam, vec, rigid).

        A Sturm count tells how many there are, so eigsh is asked for exactly those. This is what
        keeps a block whose spectrum starts far above the cut cheap: the membrane block of a free
        flat plate has only its three rigid modes below the bending cut, while its first elastic
        modes sit far above it, near tight clusters of drilling (rz) modes that ARPACK can take
        ~1e5 iterations to separate if asked for even one of them (the drilling modes sit at the
        thickness-shear frequency, :func:`.elements.shell_common.rotary_mass`).
        """
        if self.dense:
            lam, vec, rigid, _ = self._solve(0)
            return lam, vec, rigid
        try:
            count = self.count_below(lam_cut * (1.0 + STURM_MARGIN), rigid_expected)
        except SingularMatrixError:
            self.solver()  # a massless mechanism: raises the error that explains it
            raise
        want = count if cap is None else min(count, cap)
        if want == 0:
            n = self.K.shape[0]
            return np.zeros(0), np.zeros((n, 0)), np.zeros(0, dtype=bool)
        lam, vec, rigid, _ = self._solve(want)
        return lam, vec, rigid


def solve_pencil(Kr, Mr, n_modes: int | None = None, f_max: float | None = None, free: bool = False,
                 keep_factor: bool = False, axes=None):
    """(lambda, vectors, rigid mask, ShiftedInverse or None) of the constrained pencil: the first
    ``n_modes`` elastic modes and/or all up to ``f_max`` [Hz], plus the rigid-body modes met on
    the way (up to six more are looked for when ``free``). Unsorted across groups; vectors are
    mass-normalised. ``keep_factor``: also return the groups' factorisations for reuse.
    ``axes``: per constrained DOF, the axis (0-2) of a translation, -1 for a rotation; it names
    the bending group of a flat structure, solved first (:func:`_bending_group`).

    With ``f_max`` every group is counted (Sturm) below the cut, so no request has to grow.
    """
    with limited():
        return _solve_pencil(Kr, Mr, n_modes, f_max, free, keep_factor, axes)


def _bending_group(groups, dense, axes) -> int | None:
    """The group that moves along one translation axis only, when exactly one of the large groups
    does: the bending (out-of-plane) DOFs of a flat structure, whose spectrum starts far below
    the membrane group's (which moves along two). Ordering by it instead of estimating each
    group's first eigenvalue saves a factorisation and inverse iterations of the other group on
    the first solve of a pattern (112k-DOF plate, 10 fresh processes: median 2.50 -> 2.04 s; 1M DOF:
    34.5 -> 28.2 s, 5.6 -> 4.8 GB); a wrong guess costs only time,
    since the other groups are then counted (Sturm) below the cut like any other."""
    if axes is None:
        return None
    axes = np.asarray(axes)
    single = [g for g, idx in enumerate(groups)
              if not dense[g] and np.unique(axes[idx][axes[idx] >= 0]).size == 1]
    return single[0] if len(single) == 1 else None


def _solve_pencil(Kr, Mr, n_modes, f_max, free, keep_factor, axes):
    lay, K, M = layout(Kr, Mr)
    n = K.shape[0]
    extra = 6 if free else 0
    lam_cut = (2.0 * np.pi * f_max) ** 2 if f_max is not None else np.inf
    blocks = []
    for g, idx in enumerate(lay.groups):
        Kb, Mb = lay.block(g, K, M)
        blocks.append(_Block(idx, Kb, Mb, lambda g=g, Kb=Kb: lay.lower(g, Kb)))
    order = list(range(len(blocks)))
    if len(blocks) > 1:
        start = lay.start
        if np.isnan(start).any():
            bending = _bending_group(lay.groups, [b.dense for b in blocks], axes)
            start = ([-np.inf if b.dense else 0.0 if g == bending else np.inf for g, b in enumerate(blocks)]
                     if bending is not None else [b.first_eigenvalue(extra) for b in blocks])
        order.sort(key=lambda g: start[g])
    lams, vecs, rigids = [], [], []
    cap = None if n_modes is None else n_modes + extra
    for g in order:
        block = blocks[g]
        if np.isinf(lam_cut):
            lam, v, rigid = block.modes(cap, n_modes)
        else:
            lam, v, rigid = block.modes_below(lam_cut, cap, rigid_expected=free)
        elastic_here = lam[~rigid]
        lay.start[g] = -np.inf if block.dense else elastic_here.min() if elastic_here.size else lam_cut * (1 + STURM_MARGIN)
        vec = np.zeros((n, v.shape[1]))
        vec[block.idx] = v
        lams.append(lam)
        vecs.append(vec)
        rigids.append(rigid)
        elastic = np.sort(np.concatenate([l[~r] for l, r in zip(lams, rigids)]))
        if n_modes is not None and elastic.size >= n_modes:
            lam_cut = min(lam_cut, elastic[n_modes - 1])
    shifted = ShiftedInverse(n, [(b.idx, b.sigma, b.solver()) for b in blocks]) if keep_factor else None
    return np.concatenate(lams), np.hstack(vecs), np.concatenate(rigids), shifted


def _describe_rigid(full_vectors):
    """The full DOFs that move most in the given (full-length) modes, as 'node 3 uy' text."""
    full = np.abs(full_vectors).max(axis=1)
    top = np.argsort(full)[::-1][:6]
    top = top[full[top] > 1e-3 * full[top[0]]]
    return ", ".join(f"node {d // NDOF} {DOF_NAMES[d % NDOF]}" for d in top)


def eigenpairs(Kr, Mr, n_modes: int | None = None, f_max: float | None = None, free: bool = False):
    """Eigenpairs (lambda, vectors, rigid mask) of constrained matrices (sparse or dense): the first
    ``n_modes`` elastic modes and/or all up to ``f_max`` [Hz], plus the rigid-body modes met on the
    way (up to six more are looked for when ``free``). Unsorted across uncoupled DOF groups; vectors
    are mass-normalised. This is the engine of :func:`solve_modes` for callers that hold plain
    matrices (updating, studies); it raises nothing for rigid-body modes. See
    :func:`.blocks.solve_pencil`.
    """
    lam, vec, rigid, _ = solve_pencil(sp.csr_matrix(Kr), sp.csr_matrix(Mr), n_modes, f_max, free)
    return lam, vec, rigid


def solve_modes(model, n_modes: int | None = None, f_max: float | None = None, K=None, M=None,
                keep_factor: bool = False) -> Modes:
    """The first elastic modes of ``model``: K phi = omega^2 M phi, phi^T M phi = 1.

    Rigid-body modes of a free model (``model.free``) are counted and returned apart; a model not
    declared free that has one raises :class:`ModelError` naming the DOFs that move. Asking for
    more modes than the model has returns all of them (``len(frequencies)`` tells how many).
    See :func:`eigenpairs` for the solver.

    Parameters
    ----------
    model : pcbdyn.fe.Model
        Nodes, element sets and constraints (a board's is ``board.build().model``).
    n_modes : int, optional
        How many elastic modes; with ``f_max`` too, the first ``n_modes`` of those up to ``f_max``
        (default: 10 modes when neither is given).
    f_max : float, optional
        Every elastic mode up to this frequency [Hz].
    K, M : sparse matrices, optional
        The model's assembled full stiffness and mass matrices, when the caller has them (skips
        the assembly).
    keep_factor : bool
        Keep the factorisations in ``Modes.shifted`` for static and FRF solves (see the module doc).

    Returns
    -------
    Modes
        ``frequencies`` [Hz], full-length mass-normalised ``shapes`` (one column per mode),
        ``rigid_shapes`` and ``n_rigid`` of a free model.

    Examples
    --------
    A 100 x 20 x 1 mm aluminium strip clamped at x = 0 (Euler-Bernoulli: 82 Hz; the plate is
    stiffer by its width's Poisson restraint):

    >>> from pcbdyn.fe import Model, ShellProperty
    >>> from pcbdyn.fe.generate import nodes_where, rectangle
    >>> nodes, cells = rectangle(0.1, 0.02, 20, 4)
    >>> strip = Model(nodes)
    >>> _ = strip.add("plate", "quad4", cells, ShellProperty(E=70e9, nu=0.3, rho=2700.0, t=1e-3))
    >>> strip.fix(nodes_where(nodes, x=0.0))
    >>> modes = solve_modes(strip, n_modes=3)
    >>> print(modes.frequencies.round(1))
    [ 83.4 523.6 827.9]
    >>> modes.shapes.shape, modes.n_rigid
    ((630, 3), 0)
    """
    if n_modes is None and f_max is None:
        n_modes = 10
    if n_modes is not None and int(n_modes) < 1:
        raise ValueError(f"n_modes must be a positive integer, got {n_modes}")
    if f_max is not None and not f_max > 0:
        raise ValueError(f"f_max must be a positive frequency in Hz, got {f_max}")
    red, Kr, Mr = reduced_system(model, K, M)
    n = Kr.shape[0]
    if n == 0:
        raise ModelError("the model has no free DOF: every DOF is fixed or untouched by an element")
    if np.any(Mr.diagonal() < 0):
        raise ModelError("the mass matrix has negative diagonal terms: check densities and masses")
    axes = np.where(red.independent % NDOF < 3, red.independent % NDOF, -1)
    lam, vec, rigid, shifted = solve_pencil(Kr, Mr, n_modes, f_max, model.free, keep_factor, axes)
    return select_modes(lam, vec, rigid, red, red.expand, n_modes, f_max, model.free, shifted)


def select_modes(lam, vec, rigid, red, expand, n_modes=None, f_max=None, free: bool = False, shifted=None) -> Modes:
    """The :class:`Modes` of eigenpairs (lambda, vectors, rigid mask) of a model's pencil, whose vectors
    ``expand`` makes full-length (``red``: the model's constraint reduction): elastic ones sorted, the
    first ``n_modes`` and/or those up to ``f_max``; a zero-frequency mode of a model not ``free`` and a
    negative eigenvalue are errors."""
    if rigid.any() and not free:
        raise ModelError(
            f"the model has {int(rigid.sum())} zero-frequency (rigid-body or mechanism) mode(s) but "
            f"is not declared free; the DOFs moving most: {_describe_rigid(expand(vec[:, rigid]))}. "
            "Add supports (fixed DOFs, springs) there, or set model.free = True"
        )
    lam_e, vec_e = lam[~rigid], vec[:, ~rigid]
    if np.any(lam_e < 0):
        raise ModelError(
            f"negative eigenvalue {lam_e.min():.3e}: the stiffness matrix is not positive "
            "semi-definite (check element properties: E, thickness, spring constants)"
        )
    order = np.argsort(lam_e, kind="stable")
    f = np.sqrt(lam_e[order]) / (2.0 * np.pi)
    keep = order[f <= f_max] if f_max is not None else order
    if n_modes is not None:
        keep = keep[:n_modes]
    return Modes(np.sqrt(lam_e[keep]) / (2.0 * np.pi), expand(vec_e[:, keep]), expand(vec[:, rigid]), red, shifted)
