"""The catalogue of candidate effects: effects a model may lack, each one scalar parameter whose
nominal value is zero (issue 7, step 4).

A candidate is a catalogue kind (``point_mass``, ``ground_spring``, ``edge_stiffness``,
``region_stiffness``, ``stiffener``, ``line_mass``, ``region_mass``), a place and a parameter. Every kind is a
plugin module of this package that registers an object (:func:`register`, into :data:`KINDS`) with

- ``name``, ``report_as`` (the catalogue type reported), ``param`` (what the parameter is),
  ``unit`` (SI), ``scale`` (a typical magnitude), ``lower`` (the least physical value),
  ``options`` (names ``generate`` accepts);
- ``generate(layout, **options) -> [Candidate]``: candidates on a mesh (:mod:`.layout`);
- ``blocks(model, candidates) -> [Blocks]``: element matrices of dK/dp and dM/dp of all the
  candidates at once, vectorised over cells; ``uses_properties`` (optional, False by default): True
  when they depend on the model's element properties, not only on its mesh (a region's own
  stiffness), so that they cannot be kept from one parameter value to the next (:class:`BlockCache`);
- ``apply(model, candidate, value) -> Model``: a copy of the model carrying the effect;
- ``place(layout, candidate) -> Candidate``: the same effect (place and extent) on another
  mesh's layout (a finer mesh, as a test bench's truth model is);
- ``whole(candidates, i) -> int`` (optional): the candidate of which candidate ``i`` is a piece (a
  stiffener's whole line), tried beside it by the search (:mod:`.select`).
- ``together`` (optional): kinds that the same body brings to the same nodes (a heat sink's mass
  beside its stiffness, a bracket's spring beside its mass), each tried with it as one addition of two
  effects by the search (:mod:`.halves`);
- ``saturates`` (optional, False by default): True when the effect stiffens the modes near it up to a
  pin or a clamp (a support), so that the search screens more of its candidates at large magnitudes
  (:func:`.scan.saturated`; its optional ``saturated_values`` (multiples of ``scale``) and
  ``saturated_screen`` (how many) replace the screen's defaults);
- ``moved_value(old, new, value) -> float`` (optional; the same value by default): the magnitude a
  trial of candidate ``new`` in place of ``old`` at ``value`` starts from, a step of the local search
  (:func:`.select.refine`): a region's stiffness change keeps its integral over the board;
- ``coarse`` (optional, False by default): True when the kind's candidates lie on a grid coarser than
  the mesh (a region's patches of 20 and 40 mm), so that an addition the held-out folds refuse may be
  a real effect the grid misplaces: the search walks it before refusing it (:func:`.select.search`).

Every effect enters K and M linearly in its parameter, so dK/dp and dM/dp are exact and the
same at every value, and the first-order eigenvalue sensitivity (thesis eq. 3.11 with k = i)
d lambda_i / dp = phi_i^T (dK/dp - lambda_i dM/dp) phi_i is a sum of element quadratic forms
computed for all candidates of a kind in one pass (:func:`effect_forms`, :func:`eigenvalue_columns`).
A new kind of effect is one new module plus its import in :mod:`pcbdyn.diagnosis`.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from ..fe import MassProperty
from ..fe.assembly import scatter
from ..fe.mesh import element_dofs
from ..updating.sensitivity import eigen_derivatives

#: catalogue name -> plugin object, filled by :func:`register` as the kind modules are imported (by
#: :mod:`pcbdyn.diagnosis`, in the order candidates are generated). ``point_inertia`` is the
#: rotary-inertia parameter of a point mass (reported as a ``point_mass``).
KINDS: dict = {}


def register(*plugins) -> None:
    """Add catalogue kinds (plugin objects with a ``name``) to :data:`KINDS`."""
    for plugin in plugins:
        KINDS[plugin.name] = plugin


class CatalogueError(ValueError):
    """An unknown kind or a bad option, with what to use instead."""


@dataclass(frozen=True, eq=False)
class Candidate:
    """One candidate effect. ``at`` (x, y) [m] (x, y, z on a structure in 3-D) is its representative
    point (node, segment or path midpoint, region centroid); ``geometry`` holds its extent in metres
    (``segment``: two end points, ``path``/``polygon``: vertices); ``nodes`` the nodes it touches;
    ``data`` what its kind needs to build it (edges, cells, weights; on a structure of several plates
    the ``plate``, reported). ``prime``: a prime suspect (an excitation or response point). The
    parameter's nominal value is zero."""

    kind: str
    name: str
    at: tuple
    nodes: np.ndarray
    geometry: dict = field(default_factory=dict)
    data: dict = field(default_factory=dict)
    prime: bool = False

    @property
    def spec(self):
        return kind(self.kind)

    @property
    def unit(self) -> str:
        return self.spec.unit

    @property
    def nominal(self) -> float:
        return 0.0

    @property
    def between_nodes(self) -> bool:
        """Placed at a point, not on nodes: ``data["point_weights"]`` interpolate it from ``nodes``
        (a support, :mod:`.support`), so it is the same effect on any mesh."""
        return "point_weights" in self.data

    def describe(self) -> dict:
        """JSON-ready description in mm (the shape of diagnose's ``effects`` entries)."""
        d = {"type": self.spec.report_as, "name": self.name, "parameter": self.spec.param,
             "unit": self.unit, "at_mm": [round(1e3 * float(v), 3) for v in self.at]}
        if self.data.get("plate") is not None:
            d["plate"] = self.data["plate"]
        for key, pts in self.geometry.items():
            d[f"{key}_mm"] = (1e3 * np.asarray(pts)).round(3).tolist()
        return d


@dataclass
class Blocks:
    """Element matrices of dK/dp, dM/dp at unit parameter: cells ``conn`` (n, npc), ``Ke``/``Me``
    (n, 6 npc, 6 npc) in global axes, and ``owner`` (n,): the candidate index of each cell."""

    conn: np.ndarray
    Ke: np.ndarray
    Me: np.ndarray
    owner: np.ndarray


class SpreadMass:
    """Base of the kinds whose parameter is a mass m spread over the candidate's nodes by the kind's
    ``weights(model, candidate)`` (summing to one) on the three translations: M is linear in m, K does
    not depend on it."""

    def blocks(self, model, candidates) -> list:
        """Blocks of dM/dm; dK = 0."""
        nodes = np.concatenate([c.nodes for c in candidates])
        Me = np.zeros((nodes.size, 6, 6))
        Me[:, [0, 1, 2], [0, 1, 2]] = np.concatenate([self.weights(model, c) for c in candidates])[:, None]
        owner = np.repeat(np.arange(len(candidates)), [c.nodes.size for c in candidates])
        return [Blocks(nodes[:, None], np.zeros_like(Me), Me, owner)]

    def apply(self, model, candidate, value: float):
        """A copy of ``model`` with mass ``value`` spread over the candidate's nodes."""
        m = model.copy()
        for k, (n, w) in enumerate(zip(candidate.nodes, self.weights(model, candidate))):
            m.add(f"effects.{candidate.name}.{k}", "mass", [[int(n)]], MassProperty(value * w))
        return m


def kind(name: str):
    """The plugin object of catalogue kind ``name``."""
    try:
        return KINDS[name]
    except KeyError:
        raise CatalogueError(f"unknown effect kind '{name}' (use one of {', '.join(KINDS)})") from None


def moved_value(old, new, value: float) -> float:
    """The magnitude an effect at ``value`` on candidate ``old`` starts from on candidate ``new`` (a step of
    a local search): its kind's ``moved_value`` where it has one, else ``value``."""
    move = getattr(new.spec, "moved_value", None)
    return value if move is None or old is new else move(old, new, value)


def _by_kind(candidates):
    groups: dict = {}
    for i, c in enumerate(candidates):
        groups.setdefault(c.kind, []).append(i)
    return groups


def jointly(candidates):
    """A test ``ok(values)`` that the magnitudes of ``candidates`` stay physical taken together, as
    the kinds with a ``joint`` test state it (overlapping regions' stiffness changes add up); each
    magnitude's own bound is the kind's ``lower``."""
    tests = [(idx, kind(name).joint([candidates[i] for i in idx]))
             for name, idx in _by_kind(candidates).items() if getattr(kind(name), "joint", None)]
    return lambda values: all(ok(np.asarray(values, float)[idx]) for idx, ok in tests)


class BlockCache:
    """Candidates' element blocks kept by (kind, candidate names) for the kinds that depend on the
    mesh only (not ``uses_properties``): every fit of a diagnosis asks for the same candidates on
    the same mesh again (a stiffener's embedded beam pieces, an inertia's footprint). At most
    ``size`` groups of several candidates (every candidate of a kind, whose columns each search step
    takes) and as many single candidates (each trial fit's) are kept, in two pools, the least recently
    used of a pool dropped first: a screen of forty single candidates no longer pushes out the groups
    (a card's every stiffener piece: 366 MB of blocks made again at every step)."""

    def __init__(self, size: int = 64):
        self.size, self._pools = size, (OrderedDict(), OrderedDict())

    def __getstate__(self):
        """Sent to a worker process or a Dask worker empty: the blocks are made again there when
        asked for, rather than hundreds of MB pickled with every residual."""
        return {"size": self.size}

    def __setstate__(self, state):
        self.__init__(state["size"])

    def __call__(self, model, name: str, cands) -> list:
        spec = kind(name)
        if getattr(spec, "uses_properties", False):
            return spec.blocks(model, cands)
        key = (name, tuple(c.name for c in cands))
        kept = self._pools[len(cands) > 1]
        if key in kept:
            kept.move_to_end(key)
        else:
            kept[key] = spec.blocks(model, cands)
            while len(kept) > self.size:
                kept.popitem(last=False)
        return kept[key]


def _blocks(model, name, cands, cache=None) -> list:
    return cache(model, name, cands) if cache is not None else kind(name).blocks(model, cands)


def derivatives(model, candidate, cache: BlockCache | None = None):
    """(dK/dp, dM/dp) of one candidate as full-size CSR matrices (before constraints); exact.
    ``cache``: a :class:`BlockCache` to take its element blocks from."""
    n = model.n_dof
    K, M = sp.csr_matrix((n, n)), sp.csr_matrix((n, n))
    for b in _blocks(model, candidate.kind, [candidate], cache):
        K = K + scatter(n, b.conn, b.Ke)
        M = M + scatter(n, b.conn, b.Me)
    return K, M


def add_effect(model, candidate, value: float):
    """A copy of ``model`` carrying ``candidate`` at parameter ``value`` (SI)."""
    if not np.isfinite(value):
        raise CatalogueError(f"{candidate.name}: the effect's value must be finite, got {value}")
    return candidate.spec.apply(model, candidate, float(value))


def place(layout, candidate) -> Candidate:
    """``candidate`` (made on some mesh) placed on ``layout``'s mesh, under the same name."""
    return replace(candidate.spec.place(layout, candidate), name=candidate.name, prime=candidate.prime)


def effect_forms(model, basis: np.ndarray, shapes: np.ndarray, candidates, cache: BlockCache | None = None):
    """(BK, BM), each (n_candidates, n_basis, n_shapes): phi_k^T dK/dp phi_i and phi_k^T dM/dp phi_i
    for full-length ``basis`` columns k and ``shapes`` columns i, summed over each candidate's
    cells (the terms of the eigenvalue and eigenvector derivatives, thesis eqs. 3.6 and 3.11).
    ``cache``: a :class:`BlockCache` to take the element blocks from."""
    BK = np.zeros((len(candidates), basis.shape[1], shapes.shape[1]))
    BM = np.zeros_like(BK)
    for name, idx in _by_kind(candidates).items():
        cands = [candidates[i] for i in idx]
        for b in _blocks(model, name, cands, cache):
            dofs = element_dofs(b.conn)
            pb, ps = basis[dofs], shapes[dofs]  # (n_cells, nd, n_basis), (n_cells, nd, n_shapes)
            S = sp.csr_matrix((np.ones(b.owner.size), (b.owner, np.arange(b.owner.size))),
                              shape=(len(cands), b.owner.size))
            for E, out in ((b.Ke, BK), (b.Me, BM)):
                if np.any(E):
                    per_cell = np.einsum("cak,cab,cbi->cki", pb, E, ps, optimize=True)
                    out[idx] += (S @ per_cell.reshape(b.owner.size, -1)).reshape(len(cands), *per_cell.shape[1:])
    return BK, BM


def eigenvalue_columns(model, modes, candidates) -> np.ndarray:
    """d lambda_i / dp for every mode i (rows) and candidate (columns) [rad^2/s^2 per SI unit],
    from mass-normalised full-length shapes (``fe.modal.Modes``): thesis eq. 3.6 on the candidates'
    element forms (:func:`pcbdyn.updating.sensitivity.eigen_derivatives`)."""
    BK, BM = effect_forms(model, modes.shapes, modes.shapes, candidates)
    return eigen_derivatives(BK, BM, modes.omega2, np.arange(modes.shapes.shape[1]))[0].T


def frequency_columns(model, modes, candidates) -> np.ndarray:
    """d f_i / dp [Hz per SI unit], (n_modes, n_candidates): d lambda / dp / (8 pi^2 f_i)."""
    f = np.asarray(modes.frequencies, dtype=float)
    return eigenvalue_columns(model, modes, candidates) / (8.0 * np.pi**2 * f)[:, None]


def active(model, candidates, cache: BlockCache | None = None) -> np.ndarray:
    """True for candidates that touch at least one DOF the constraints leave free (a spring on
    a clamped edge changes nothing and is dropped). ``cache``: the :class:`BlockCache` to make the
    element blocks in, so that the search's first columns of the same candidates find them there."""
    free = np.ones(model.n_dof, dtype=bool)
    free[list(model.fixed)] = False
    keep = np.zeros(len(candidates), dtype=bool)
    for name, idx in _by_kind(candidates).items():
        for b in _blocks(model, name, [candidates[i] for i in idx], cache):
            f = free[element_dofs(b.conn)]
            mask = f[:, :, None] & f[:, None, :]
            hit = (np.abs(b.Ke) * mask).max(axis=(1, 2)) + (np.abs(b.Me) * mask).max(axis=(1, 2)) > 0
            keep[np.asarray(idx)[np.unique(b.owner[hit])]] = True
    return keep


def generate(layout, kinds=None, cache: BlockCache | None = None, **options) -> list:
    """Candidates of the given kinds (default: all) on ``layout`` (:mod:`.layout`). ``options`` go
    to the kinds that accept them (``spacing``, ``segments``, ``patch``, ...). Candidates that
    cannot act on the constrained model are dropped (:func:`active`, its blocks made in ``cache``)."""
    names = list(KINDS) if kinds is None else list(kinds)
    accepted = {o for name in names for o in kind(name).options}
    unknown = sorted(set(options) - accepted)
    if unknown:
        raise CatalogueError(f"generate: unknown option(s) {', '.join(unknown)} for kinds {', '.join(names)} "
                             f"(options: {', '.join(sorted(accepted))})")
    out = []
    for name in names:
        k = kind(name)
        out += k.generate(layout, **{o: v for o, v in options.items() if o in k.options})
    return [c for c, a in zip(out, active(layout.model, out, cache)) if a] if out else []


def node_candidates(kind_name: str, layout, spacing: float | None = None) -> list:
    """One candidate per grid node (:meth:`Layout.grid_nodes`) plus one at every prime suspect; on a
    structure of several plates each knows its node's plate (``data["plate"]``, reported)."""
    prime = {int(n): s for s, n in layout.suspects.items()}
    nodes = np.union1d(layout.grid_nodes(spacing), np.array(sorted(prime), dtype=np.int64))
    pts = layout.points
    return [Candidate(kind_name, f"{kind_name}@{prime.get(int(n), f'n{n}')}", tuple(pts[n]), np.array([n]),
                      data={"plate": layout.plate_of(n)} if layout.plates else {}, prime=int(n) in prime)
            for n in nodes]


def on_nearest_node(layout, candidate) -> Candidate:
    """``candidate`` (of one node) on the node of ``layout`` nearest to its point, at that node."""
    n = layout.nearest_node(candidate.at)
    return replace(candidate, at=tuple(layout.points[n]), nodes=np.array([n]))


def weighted_centre(candidates, values) -> np.ndarray:
    """The magnitude-weighted centre (x, y) [m] of the candidates' points (their mean where the
    magnitudes do not add up to a positive total): where shares of one effect put it."""
    v = np.asarray(values, float)
    xy = np.array([c.at for c in candidates], float)
    w = v / v.sum() if v.sum() > 0 else np.full(v.size, 1.0 / v.size)
    return w @ xy


class AlongSides:
    """``generate`` and ``place`` of a kind acting along runs of a side or support line (a
    subclass sets ``name``): every run of consecutive pieces of ``segments`` per side is a
    candidate, and an effect goes to another mesh along the side nearest to its segment."""

    options = ("segments",)

    def generate(self, layout, segments: int = 4) -> list:
        if not layout.planar:  # sides of a plate in one plane only
            return []
        return [chain_candidate(self.name, layout, f"{side}[{i}]" if i == j else f"{side}[{i}-{j}]", chain,
                                run=(side, i, j)) for side, (i, j), chain in layout.segment_runs(segments)]

    def place(self, layout, candidate):
        return chain_candidate(self.name, layout, "placed", layout.side_chain(candidate.geometry["segment"]))


def chain_candidate(kind_name: str, layout, label: str, chain: np.ndarray, run=None) -> Candidate:
    """A candidate along a node chain of a boundary segment; ``at`` is the point of the chain
    halfway along its length; ``run``: (side, first piece, last piece) where it is a run of a side's
    pieces (:meth:`.layout.Layout.segment_runs`), kept in ``data`` for the local moves."""
    p = layout.xy[chain]
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    mid = np.array([np.interp(0.5 * s[-1], s, p[:, 0]), np.interp(0.5 * s[-1], s, p[:, 1])])
    data = {"edges": np.column_stack([chain[:-1], chain[1:]]), "length": float(s[-1])}
    if run is not None:
        data["run"] = run
    return Candidate(kind_name, f"{kind_name}@{label}", tuple(mid), chain, {"segment": p[[0, -1]]}, data)
