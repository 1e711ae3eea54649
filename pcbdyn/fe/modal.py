"""Real normal modes of undamped models: K phi = omega^2 M phi, mass-normalised (phi^T M phi = 1).

Large systems: ARPACK (eigsh) in shift-invert mode about a small negative shift sigma, with
(K - sigma M)^-1 applied by a CHOLMOD factorisation (:mod:`.linsolve`). The shift makes the
operator positive definite even for a free model, and is kept far below the first elastic
eigenvalue so that the wanted eigenvalues stay well separated after inversion. Small systems
(or requests for most of the spectrum) use dense LAPACK.

Rigid-body modes are recognised per mode, independently of units and mesh size: a mass-normalised
mode is rigid when its strain energy lambda = phi^T K phi is below ``RIGID_RTOL`` times its gross
energy |phi|^T |K| |phi|. For an exact rigid motion the element forces cancel to round-off
(ratio ~1e-17..1e-16); for an elastic mode the ratio falls with (element size / wavelength)^4 and
with the thinness of shells, but stays far above the threshold (measured on free square plates:
5.7e-8 for 128 x 128 quads at a/t = 100, 2.3e-9 for 64 x 64 at a/t = 1000).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from .assembly import assemble
from .constraints import Reduction, build_reduction
from .linsolve import SingularMatrixError, factorize
from .mesh import DOF_NAMES, NDOF
from .model import ModelError

#: strain energy / gross energy below which a mode counts as a rigid-body (zero-frequency) mode
RIGID_RTOL = 1e-12
#: reduced systems up to this size are solved densely (all eigenpairs at once)
DENSE_MAX = 600


@dataclass
class Modes:
    """Elastic modes (frequencies in Hz, full-length mass-normalised shapes as columns) and the
    rigid-body modes found in a free model (full-length, mass-normalised)."""

    frequencies: np.ndarray
    shapes: np.ndarray
    rigid_shapes: np.ndarray
    reduction: Reduction

    @property
    def n_rigid(self) -> int:
        return self.rigid_shapes.shape[1]

    @property
    def omega2(self) -> np.ndarray:
        """Elastic eigenvalues omega^2 [rad^2/s^2]."""
        return (2.0 * np.pi * self.frequencies) ** 2


def reduced_system(model, K=None, M=None):
    """(reduction, Kr, Mr): the constrained matrices as CSC.

    When the model has no multi-point constraints, the reduction only drops DOFs, and the reduced
    matrices are taken by row/column selection instead of the triple product T^T A T.
    """
    if K is None or M is None:
        K, M = assemble(model)
    red = build_reduction(model, K, M)
    return red, reduce_matrix(red, K), reduce_matrix(red, M)


def reduce_matrix(red: Reduction, A) -> sp.csc_matrix:
    """T^T A T, by selection when T is a pure selection of DOFs (one unit entry per column)."""
    if red.T.nnz == red.independent.size:
        idx = red.independent
        return sp.csr_matrix(A)[idx][:, idx].tocsc()
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


def _describe_rigid(red, vec):
    """The full DOFs that move most in the given reduced modes, as 'node 3 uy' text."""
    full = np.abs(red.expand(vec)).max(axis=1)
    top = np.argsort(full)[::-1][:6]
    top = top[full[top] > 1e-3 * full[top[0]]]
    return ", ".join(f"node {d // NDOF} {DOF_NAMES[d % NDOF]}" for d in top)


def uncoupled_blocks(Kr, Mr) -> list[np.ndarray]:
    """Index sets of the DOF groups that K and M do not couple (exact zeros only), largest first.

    A flat plate in a coordinate plane splits exactly into its bending (uz, rx, ry) and membrane
    (ux, uy, rz) DOFs; solving the two halves apart needs about a quarter of the factor fill each.
    Groups of at most ``DENSE_MAX`` DOFs are lumped into one last block.
    """
    n = Kr.shape[0]
    pattern = (abs(Kr) + abs(Mr)).tocsr()
    pattern.eliminate_zeros()
    n_comp, label = connected_components(pattern, directed=False)
    if n_comp == 1:
        return [np.arange(n)]
    sizes = np.bincount(label)
    big = np.flatnonzero(sizes > DENSE_MAX)
    big = big[np.argsort(-sizes[big], kind="stable")]
    groups = [np.flatnonzero(label == c) for c in big]
    small = np.flatnonzero(sizes[label] <= DENSE_MAX)
    if small.size:
        groups.append(small)
    return groups


class _Block:
    """One uncoupled DOF group: its matrices, its shift-invert factorisation (made once, reused
    when more modes are asked) and the eigenpairs found so far."""

    def __init__(self, idx, Kb, Mb):
        self.idx, self.K, self.M = idx, sp.csr_matrix(Kb), sp.csr_matrix(Mb)  # CSR: faster products
        dk, dm = Kb.diagonal(), Mb.diagonal()
        both = (dk > 0) & (dm > 0)
        self.scale = float(np.median(dk[both] / dm[both])) if both.any() else 1.0
        self.sigma = -1e-9 * self.scale
        self.dense = Kb.shape[0] <= DENSE_MAX
        self._solver = None

    def solver(self):
        if self._solver is None:
            try:
                self._solver = factorize(self.K - self.sigma * self.M)
            except SingularMatrixError as exc:
                raise ModelError(
                    "K + s M is singular for s > 0: some DOFs carry neither stiffness nor mass in "
                    "some direction (a massless mechanism); add supports or springs there"
                ) from exc
        return self._solver

    def first_eigenvalue(self, n_skip: int) -> float:
        """A cheap upper estimate of the block's first eigenvalue after ``n_skip`` (rigid) ones:
        three block inverse iterations and a Rayleigh-Ritz step. Used only to order the blocks."""
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

    def modes(self, want: int, n_needed: int | None, lam_cut: float, probe: bool = False):
        """Mass-normalised eigenpairs from the lowest up, until ``n_needed`` elastic modes are
        found, an elastic eigenvalue exceeds ``lam_cut``, or the block has no more:
        (lam, vec, rigid).

        ``probe``: first try ``want`` modes at a loose ARPACK tolerance (1e-6 on the Ritz vectors,
        so ~1e-12 on Rayleigh-quotient eigenvalues); if none is rigid and all already pass
        ``lam_cut`` they are returned (they lie above every wanted mode and will not be kept),
        else the search restarts at full accuracy.
        """
        n = self.K.shape[0]
        absK = abs(self.K)
        tol = 1e-6 if probe else 0.0
        while True:
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
                op = self.solver().operator()
                _, vec = spla.eigsh(self.K, k=want, M=self.M, sigma=self.sigma, which="LM", OPinv=op, tol=tol)
                exhausted = False
            vec = _mass_normalise(vec, self.M)
            lam = np.einsum("ij,ij->j", vec, self.K @ vec)
            gross = np.einsum("ij,ij->j", np.abs(vec), absK @ np.abs(vec))
            rigid = np.abs(lam) <= RIGID_RTOL * gross
            lam_e = np.sort(lam[~rigid])
            if tol > 0 and not exhausted:
                tol = 0.0
                if not rigid.any() and lam_e.size > 0 and lam_e[0] > lam_cut:
                    return lam, vec, rigid
                continue
            if (
                exhausted
                or (n_needed is not None and lam_e.size >= n_needed)
                or (lam_e.size > 0 and lam_e[-1] > lam_cut)
            ):
                return lam, vec, rigid
            want = max(2 * want, 6)


def solve_modes(model, n_modes: int | None = None, f_max: float | None = None, K=None, M=None) -> Modes:
    """The first elastic modes of ``model``: ``n_modes`` of them, or all up to ``f_max`` [Hz], or,
    with both, the first ``n_modes`` of those up to ``f_max`` (default: 10 modes).

    Rigid-body modes of a free model (``model.free``) are counted and returned apart; a model not
    declared free that has one raises :class:`ModelError` naming the DOFs that move. Asking for
    more modes than the model has returns all of them (``len(frequencies)`` tells how many).
    ``K, M``: already assembled full matrices (skips the assembly). Uncoupled DOF groups (see
    :func:`uncoupled_blocks`) are solved one by one, the one whose spectrum starts lowest first;
    after it, a group is only searched below the highest eigenvalue still wanted.
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
    extra = 6 if model.free else 0
    lam_cut = (2.0 * np.pi * f_max) ** 2 if f_max is not None else np.inf
    groups = uncoupled_blocks(Kr, Mr)
    if len(groups) == 1:
        blocks = [_Block(groups[0], Kr, Mr)]
    else:  # the block whose spectrum starts lowest holds most wanted modes: solve it first
        blocks = [_Block(idx, Kr[idx][:, idx], Mr[idx][:, idx]) for idx in groups]
        blocks.sort(key=lambda b: b.first_eigenvalue(extra))
    lams, vecs, rigids = [], [], []
    first = (n_modes if n_modes is not None else 20) + extra
    for block in blocks:
        idx = block.idx
        # after the first block, probe with one elastic mode: often the block starts above the cut
        if np.isinf(lam_cut):
            lam, v, rigid = block.modes(first, n_modes, lam_cut)
        else:
            lam, v, rigid = block.modes(1 + extra, n_modes, lam_cut, probe=True)
        vec = np.zeros((n, v.shape[1]))
        vec[idx] = v
        lams.append(lam)
        vecs.append(vec)
        rigids.append(rigid)
        elastic = np.sort(np.concatenate([l[~r] for l, r in zip(lams, rigids)]))
        if n_modes is not None and elastic.size >= n_modes:
            lam_cut = min(lam_cut, elastic[n_modes - 1])
    lam, vec, rigid = np.concatenate(lams), np.hstack(vecs), np.concatenate(rigids)
    if rigid.any() and not model.free:
        raise ModelError(
            f"the model has {int(rigid.sum())} zero-frequency (rigid-body or mechanism) mode(s) but "
            f"is not declared free; the DOFs moving most: {_describe_rigid(red, vec[:, rigid])}. "
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
    return Modes(np.sqrt(lam_e[keep]) / (2.0 * np.pi), red.expand(vec_e[:, keep]), red.expand(vec[:, rigid]), red)
