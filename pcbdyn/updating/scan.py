"""A coarse scan before Gauss-Newton for parameters whose start may be decades off (thesis section 7.4.2
scans a guide's stiffness between its extremes before updating it).

Sensitivity-based updating is Newton's method: it finds the minimum of the basin it starts in. A
stiffness known to within decades, or a parameter whose bounds span a decade or more, is first scanned on
a geometric grid between its bounds (jointly for up to :data:`MAX_SCANNED` such parameters, the others
held at their start), each grid point solved and paired and scored by the fit's own objective
(:func:`.driver.evaluate`: measured modes left unpaired first, then the sum of squares of the noise-
weighted errors). Every local minimum of the grid is a basin; the best few become the starts of the fit,
best first, so that two basins a nearly symmetric structure makes (one guide stiff and the other soft, or
the other way round) are both fitted and the better kept.

A large model is not re-solved at every grid point: the grid's points are solved on the reanalysis of
Rayleigh-Ritz, the model projected on the modes solved at the corners and middles of the grid (3 per
scanned parameter), a small dense eigenproblem per point. Where the reanalysis is not accurate (its
objective at the starts found differs from a full solve's by more than :data:`RITZ_TOL`), the grid is
solved again in full.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .driver import _better, _key, evaluate
from .iteration import paired_state
from .sensitivity import pencil_modes

#: parameters scanned jointly at most
MAX_SCANNED = 3
#: a parameter whose bounds span at least this ratio is scanned (as are those on a log scale)
WIDE = 10.0
#: grid points per decade, thinned so that the whole grid has at most MAX_POINTS points
PER_DECADE = 2.0
MAX_POINTS = 300
#: starts kept: the best basins, each within this factor of the best's objective
MAX_STARTS = 3
BASIN_FACTOR = 10.0
#: models with at least this many DOF are scanned on the reanalysis
RITZ_DOF = 1000
#: the reanalysis is accurate when its objective at every start is within this (in units of the noise's
#: chi^2, or this fraction of it) of a full solve's, with the same modes paired
RITZ_TOL = 1.0
#: interpolation points per scanned parameter of the reanalysis (degree 3)
NODES = 4
CHEBYSHEV = np.cos(np.pi * (np.arange(NODES) + 0.5) / NODES)


@dataclass
class Scan:
    """``indices``: the scanned parameters; ``values``: their grid values; ``keys``: (unpaired modes,
    objective) at every grid point (grid shape + (2,), infinite objective where the model could not be
    solved); ``starts``: parameter vectors at the best basins' minima, best first; ``solved``: "reanalysis"
    or "full"."""

    indices: list
    values: list
    keys: np.ndarray
    starts: list
    solved: str = "full"

    def to_dict(self, names) -> dict:
        return {"parameters": [names[j] for j in self.indices], "values": [v.tolist() for v in self.values],
                "starts": [[float(s[j]) for j in self.indices] for s in self.starts], "solved": self.solved}


def scanned(p0, bounds, log_scale, fixed=()) -> list:
    """[(index, low, high)] of the parameters to scan: on a log scale or with bounds spanning
    :data:`WIDE` or more, at most :data:`MAX_SCANNED` of them (the widest in decades first); a bound at
    zero or infinity is replaced by the start / or * 1e3."""
    lo, hi = (np.broadcast_to(np.asarray(v, float), np.shape(p0)) for v in bounds)
    out = []
    for j, p in enumerate(np.asarray(p0, float)):
        if j in set(fixed) or p <= 0:
            continue
        a = lo[j] if lo[j] > 0 else p / 1e3
        b = hi[j] if np.isfinite(hi[j]) else p * 1e3
        if j in set(log_scale) or b / a >= WIDE:
            out.append((j, float(a), float(b)))
    out.sort(key=lambda r: -np.log(r[2] / r[1]))
    return out[:MAX_SCANNED]


def grid(ranges) -> list:
    """Geometric grid values of each range, PER_DECADE points per decade (at least 3), thinned to at most
    MAX_POINTS points in all."""
    decades = np.array([np.log10(b / a) for _, a, b in ranges])
    per = PER_DECADE
    while np.prod(np.maximum(np.round(decades * per) + 1, 3)) > MAX_POINTS and per > 0.25:
        per *= 0.8
    return [np.geomspace(a, b, int(max(round(d * per) + 1, 3))) for (_, a, b), d in zip(ranges, decades)]


def scan(configs, p0, ranges, pairing=None, progress=None) -> Scan:
    """Score every grid point of ``ranges`` (:func:`scanned`) and pick the starts (module docstring);
    ``progress(message)`` is told what is scanned."""
    indices = [j for j, _, _ in ranges]
    values = grid(ranges)
    shape = tuple(v.size for v in values)

    def point(at):
        p = np.array(p0, float)
        p[indices] = [v[i] for v, i in zip(values, at)]
        return p

    ritz = None
    if all(c.f_x is not None and c.model(np.asarray(p0, float))[0].shape[0] >= RITZ_DOF for c in configs):
        middle = [tuple(int(round(i * (n - 1) / 2)) for i, n in zip(at, shape))
                  for at in itertools.product(range(3), repeat=len(shape))]
        ritz = [_Ritz(c, [point(at) for at in middle], ranges, p0) for c in configs]
    if progress is not None:
        progress(f"scanning {' x '.join(map(str, shape))} points" + (" on the reanalysis" if ritz else ""))
    start = evaluate(configs, np.asarray(p0, float), pairing)
    while True:
        keys = np.empty(shape + (2,))
        for at in itertools.product(*(range(n) for n in shape)):
            key = evaluate(configs, point(at), pairing) if ritz is None else _reduced(configs, ritz, point(at), pairing)
            keys[at] = (np.inf, np.inf) if key is None or key[1] is None else key
        starts, best = _starts(keys, values, indices, p0)
        if ritz is None or all(_close(evaluate(configs, p, pairing), _reduced(configs, ritz, p, pairing))
                               for p in starts):
            break
        ritz = None
        if progress is not None:
            progress("the reanalysis is not accurate here: the grid solved in full")
    if (start is not None and start[1] is not None and (best is None or _better(start, best))
            and not any(np.allclose(p0, q) for q in starts)):
        starts = [np.array(p0, float)] + starts[:MAX_STARTS - 1]  # the user's start is better than any grid point
    return Scan(indices, values, keys, starts, "full" if ritz is None else "reanalysis")


def _close(full, reduced) -> bool:
    if full is None or reduced is None or full[1] is None or reduced[1] is None:
        return full == reduced
    return full[0] == reduced[0] and abs(full[1] - reduced[1]) <= max(RITZ_TOL, RITZ_TOL * 0.05 * full[1])


class _Ritz:
    """Rayleigh-Ritz reanalysis of a configuration: its model projected on the (orthonormalised) modes
    solved at ``anchors``. A structure's matrices are polynomials of degree <= 3 in each parameter
    (:mod:`pcbdyn.fe.parametric_matrices`), so the projected ones are too: they are projected once at the
    tensor grid of :data:`NODES` Chebyshev points over the scanned ``ranges`` and interpolated at every grid
    point (exact for such a model; the check of the starts against full solves catches any other)."""

    def __init__(self, cfg, anchors, ranges, p0):
        self.cfg = cfg
        self.n = cfg.n_modes or 2 * np.size(cfg.f_x) + 4
        Phi = np.hstack([pencil_modes(*cfg.model(p)[:2], self.n)[1] for p in anchors])
        U, sv, _ = np.linalg.svd(Phi, full_matrices=False)
        B = U[:, sv > 1e-10 * sv[0]]
        self.indices = [j for j, _, _ in ranges]
        self.nodes = [0.5 * (a + b) + 0.5 * (b - a) * CHEBYSHEV for _, a, b in ranges]
        self.Kr = np.empty((NODES,) * len(ranges) + (B.shape[1],) * 2)
        self.Mr = np.empty_like(self.Kr)
        for at in itertools.product(range(NODES), repeat=len(ranges)):
            p = np.array(p0, float)
            p[self.indices] = [v[i] for v, i in zip(self.nodes, at)]
            K, M, _, _ = cfg.model(p)
            self.Kr[at], self.Mr[at] = (B.T @ np.asarray(A @ B) for A in (K, M))
        self.B = B

    def modes(self, p) -> tuple:
        Kr, Mr = self.Kr, self.Mr
        for j, v in zip(self.indices, self.nodes):
            w = _lagrange(v, p[j])
            Kr, Mr = np.tensordot(w, Kr, axes=(0, 0)), np.tensordot(w, Mr, axes=(0, 0))
        n = min(self.n, Kr.shape[0])
        lam, Y = sla.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T), subset_by_index=[0, n - 1])
        return lam, self.B @ Y


def _lagrange(nodes, x) -> np.ndarray:
    """The Lagrange weights of ``nodes`` at ``x``."""
    return np.array([np.prod([(x - b) / (a - b) for j, b in enumerate(nodes) if j != i]) for i, a in enumerate(nodes)])


def _reduced(configs, ritz, p, pairing) -> tuple | None:
    """(unpaired, objective) at ``p`` on the reanalysis; None where it cannot be solved."""
    try:
        states = [paired_state(c, *r.modes(p), pairing) for c, r in zip(configs, ritz)]
    except (np.linalg.LinAlgError, ValueError, ArithmeticError):
        return None
    return _key(configs, states)


def _starts(keys, values, indices, p0) -> list:
    shape = keys.shape[:-1]
    minima = []
    for at in itertools.product(*(range(n) for n in shape)):
        k = tuple(keys[at])
        if not np.isfinite(k[1]):
            continue
        near = [tuple(np.add(at, d)) for d in itertools.product((-1, 0, 1), repeat=len(shape)) if any(d)]
        near = [q for q in near if all(0 <= c < n for c, n in zip(q, shape))]
        if not any(_better(tuple(keys[q]), k) for q in near):
            minima.append((k, at))
    minima.sort(key=lambda m: m[0])
    chosen = []
    for k, at in minima:
        best = minima[0][0]
        if k[0] > best[0] or k[1] > BASIN_FACTOR * best[1] or len(chosen) == MAX_STARTS:
            break
        if any(max(abs(a - b) for a, b in zip(at, c)) <= 1 for c in chosen):
            continue  # a plateau's neighbour: the same basin
        chosen.append(at)
    starts = []
    for at in chosen:
        p = np.array(p0, float)
        p[indices] = [v[i] for v, i in zip(values, at)]
        starts.append(p)
    return (starts, minima[0][0]) if starts else ([np.array(p0, float)], None)
