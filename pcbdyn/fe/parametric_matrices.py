"""K(p), M(p) and their parameter derivatives of a parametric model, without re-assembling it.

Quantities enter element matrices as polynomials of degree <= 3 (:mod:`.parametric`), so every
element set's assembled values are a polynomial in the parameters it depends on, of degree <= 3 in
each. :class:`ParametricMatrices` interpolates each set once, on the tensor grid of four Chebyshev
points per parameter across the parameter's bounds, and checks the interpolant against a direct
assembly at one more point; K and M at any parameter values, and their exact derivatives, are then
sums of coefficient arrays times monomials: no element matrix is recomputed while a fit moves the
parameters (a fit of the six-part card's four parameters re-solves it hundreds of times). A
parameter that a set of its own shows to enter with a lower degree (a modulus or a density enters
linearly), or whose maker declares its power (a housing plate's E and rho), is interpolated on that
many points in the sets it shares with others, and those are checked as any other (the card's parts,
on E and their thickness: 9 assemblies each instead of 17, which halves the interpolation of a model
meshed once for a trial, as a diagnosis's rib fit does). A set that fails the check (a quantity
entering otherwise, such as a Timoshenko beam's shear term), whose maker says it is not a polynomial
in a parameter (:attr:`.parametric.SetMaker.powers`: a housing's rib in its height, whose grid would
be assembled in every re-meshed trial of a diagnosis only to fail the check) or that depends on more
than :data:`MAX_PARAMS` parameters is made again from its property at each call,
its derivatives by central differences with :meth:`.parametric.Parameter.step`, as
:meth:`.parametric.Parameter.derivatives` takes them.

All the matrices share one index (the model's assembled pattern, :class:`.assembly.SetAssembly`),
so the solvers' caches keyed by pattern (symbolic factorisations, DOF groups and their order) hit.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .assembly import SetAssembly
from .sparsity import Gather

#: interpolation degree in each parameter (the highest power a quantity enters with)
DEGREE = 3
#: largest |interpolant - direct assembly| at the check point, relative to the set's largest entry
CHECK_RTOL = 1e-9
#: sets depending on more parameters than this are made again at each call (4^k assemblies to interpolate)
MAX_PARAMS = 3
#: where the interpolant is checked, in the scaled variable of each parameter (off every node)
CHECK_AT = 0.77
#: a set touching more than this share of the pattern keeps its coefficients at full length
FULL_SHARE = 0.5
#: relative step of the central differences of the sets made at each call
REL_STEP = 1e-4


def _chebyshev(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """(the degree + 1 Chebyshev points in [-1, 1], the inverse of their Vandermonde matrix: values at
    the points -> power coefficients)."""
    nodes = np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
    return nodes, np.linalg.inv(np.vander(nodes, degree + 1, increasing=True))


_GRIDS = {d: _chebyshev(d) for d in range(DEGREE + 1)}


class _Set:
    """One element set that depends on parameters ``js`` (indices into the names), at CSR value
    positions ``pos`` (a slice: all of them): K and M as ``coef`` (n_monomials, 2, n_pos) times the
    monomials of the scaled parameters with exponents ``exps`` (n_monomials, len(js)), or ``coef``
    None when the set is made at each call."""

    def __init__(self, name, js, pos, coef=None, exps=None):
        self.name, self.js, self.pos, self.coef, self.exps = name, list(js), pos, coef, exps

    def values(self, x: np.ndarray, d: int | None = None) -> np.ndarray:
        """(2, n_pos): the K and M values at scaled parameters ``x`` (all names), or their
        derivative along scaled parameter ``d`` (an index into the names)."""
        xs = x[self.js]
        if d is None:
            w = np.prod(xs ** self.exps, axis=1)
        else:
            k = self.js.index(d)
            e = self.exps[:, k]
            others = np.delete(np.arange(len(self.js)), k)
            w = e * xs[k] ** np.maximum(e - 1, 0) * np.prod(xs[others] ** self.exps[:, others], axis=1)
        return (w @ self.coef.reshape(len(w), -1)).reshape(2, -1)


class ParametricMatrices:
    """K and M of the built parametric model ``pm`` (:class:`.parametric.ParametricModel`) as
    functions of its parameters ``names`` (values in SI, in that order; names ``pm`` lacks have zero
    derivatives), on one fixed pattern (module doc)."""

    def __init__(self, pm, names):
        self.pm, self.names = pm, list(names)
        self.asm = SetAssembly(pm.model)
        own = [j for j, nm in enumerate(self.names) if nm in pm.parameters]
        targets = {j: set(pm.parameters[self.names[j]].targets) for j in own}
        self.centre, self.half = np.zeros(len(self.names)), np.ones(len(self.names))
        for j in own:
            prm = pm.parameters[self.names[j]]
            lo, hi = (float(b) for b in prm.bounds)
            if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
                lo, hi = 0.5 * prm.value, 1.5 * prm.value
            self.centre[j], self.half[j] = 0.5 * (lo + hi), 0.5 * (hi - lo)
        self.const = np.zeros((2, self.asm.nnz))
        self.sets: list[_Set] = []
        self._degree: dict = {}  # {j: the highest power of parameter j in the sets of it alone}
        for name in self.asm.names:
            mk = pm.makers.get(name)
            shared = {j: targets[j] & set(mk.deps) for j in own} if mk is not None else {}
            js = [j for j in own if shared.get(j)]
            pos = self.asm.positions(name)
            if not js:
                self.const[:, pos] += np.array(self.asm.values(name))
                continue
            if len(js) > MAX_PARAMS or any(mk.powers.get(t, 0) is None for j in js for t in shared[j]):
                self.sets.append(_Set(name, js, pos))
                continue
            declared = [max(mk.powers[t] for t in shared[j]) if shared[j] <= mk.powers.keys() else None for j in js]
            self.sets.append(self._interpolated(name, js, pos, declared))
        touched = {j: np.zeros(self.asm.nnz, bool) for j in range(len(self.names))}
        for s in self.sets:
            for j in s.js:
                touched[j][s.pos] = True
        K = self.asm.matrix(np.zeros(self.asm.nnz))
        n = K.shape[0]
        self._plans = {j: Gather.kept(K, mask, np.arange(n), K.indices, K.shape) for j, mask in touched.items()}

    # --- direct assembly of one set ------------------------------------------------------------
    def _direct(self, name: str, p: np.ndarray) -> np.ndarray:
        """(2, n_pos) values of set ``name`` made from its property at parameters ``p`` [SI]."""
        q = dict(self.pm.quantities)
        for j, nm in enumerate(self.names):
            if nm in self.pm.parameters:
                q.update(self.pm.parameters[nm].quantities(p[j]))
        return np.array(self.asm.values(name, self.pm.makers[name].make(q)))

    def _interpolated(self, name, js, pos, declared) -> _Set:
        """The set interpolated on the Chebyshev grid of its parameters ``js`` (on as many points per
        parameter as the degree its maker ``declared`` for it, else its degree in the sets of it alone,
        else :data:`DEGREE` + 1), checked at :data:`CHECK_AT`; on the full grid where that check fails;
        a set made at each call where this one fails too."""
        full = [DEGREE] * len(js)
        degrees = [self._degree.get(j, DEGREE) if d is None else d for j, d in zip(js, declared)]
        s = self._fitted(name, js, pos, degrees)
        if s is None and degrees != full:
            s = self._fitted(name, js, pos, full)
        if s is None:
            return _Set(name, js, pos)
        if len(js) == 1:
            self._degree[js[0]] = max(self._degree.get(js[0], 0), int(s.exps.max(initial=0)))
        return s

    def _fitted(self, name, js, pos, degrees) -> _Set | None:
        """The set interpolated on the tensor grid of ``degrees[i]`` + 1 Chebyshev points along parameter
        ``js[i]``, or None where it misses a direct assembly at :data:`CHECK_AT`."""
        k = len(js)
        grid = np.empty(tuple(d + 1 for d in degrees) + (2, pos.size))
        p = self.centre.copy()
        for node in np.ndindex(*grid.shape[:k]):
            p[js] = self.centre[js] + self.half[js] * np.array([_GRIDS[d][0][i] for d, i in zip(degrees, node)])
            grid[node] = self._direct(name, p)
        coef = grid
        for axis, d in enumerate(degrees):  # values at the nodes -> power coefficients, one axis at a time
            coef = np.moveaxis(np.tensordot(_GRIDS[d][1], coef, axes=([1], [axis])), 0, axis)
        exps = np.array(list(np.ndindex(*coef.shape[:k])), dtype=np.int64).reshape(-1, k)
        coef = coef.reshape(-1, 2, pos.size)
        size = np.abs(coef).max(axis=2)  # (n_monomials, 2): each monomial's largest K and M entries
        # E and springs enter linearly; K and M apart, as M's entries are 1e-12 of K's on a housing
        keep = np.any(size > 1e-12 * np.maximum(size.max(axis=0), 1e-300), axis=1)
        whole = pos.size > FULL_SHARE * self.asm.nnz
        if whole:  # a set over most of the pattern is added without an index
            full = np.zeros((int(keep.sum()), 2, self.asm.nnz))
            full[:, :, pos] = coef[keep]
        s = _Set(name, js, slice(None) if whole else pos, full if whole else np.ascontiguousarray(coef[keep]), exps[keep])
        x = np.zeros(len(self.names))
        x[js] = CHECK_AT
        direct = self._direct(name, self.centre + self.half * x)
        got = s.values(x)
        err = np.abs((got[:, pos] if whole else got) - direct)
        if np.any(err.max(axis=1) > CHECK_RTOL * np.maximum(np.abs(direct).max(axis=1), 1e-300)):
            return None
        return s

    # --- values --------------------------------------------------------------------------------
    def _scaled(self, p) -> np.ndarray:
        return (np.asarray(p, float) - self.centre) / self.half

    def matrices(self, p) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """(K, M) at parameters ``p`` [SI], full size before constraints, on the fixed pattern."""
        p = np.asarray(p, float)
        x = self._scaled(p)
        data = self.const.copy()
        for s in self.sets:
            if s.coef is not None:
                data[:, s.pos] += s.values(x)
            else:
                data[:, s.pos] += self._direct(s.name, p)
        return self.asm.matrix(data[0]), self.asm.matrix(data[1])

    def derivatives(self, p) -> list:
        """[(dK/dp_j, dM/dp_j)] per name at ``p`` [SI] (each on the entries its sets touch)."""
        p = np.asarray(p, float)
        x = self._scaled(p)
        out = []
        for j in range(len(self.names)):
            data = np.zeros((2, self.asm.nnz))
            for s in self.sets:
                if j not in s.js:
                    continue
                if s.coef is not None:
                    data[:, s.pos] += s.values(x, d=j) / self.half[j]
                else:
                    h = self.pm.parameters[self.names[j]].step(p[j], REL_STEP)
                    up, down = p.copy(), p.copy()
                    up[j], down[j] = p[j] + h, p[j] - h
                    data[:, s.pos] += (self._direct(s.name, up) - self._direct(s.name, down)) / (2 * h)
            plan = self._plans[j]
            out.append((plan.apply(data[0]), plan.apply(data[1])))
        return out
