"""A box with its cards as one FE model (a system): the housing's shell mesh, each card's own model
(:func:`pcbdyn.board.model.build_model`, built in its board frame and placed by :mod:`pcbdyn.fe.frames`)
and the card's fixtures holding it to the housing where they touch it (:mod:`.cards`).

The meshes conform where they meet: every card node on a fixture's support line (and every standoff's
centre) is projected onto the housing's plate (a standoff on a rib: onto the rib line) and that point
is made a node of the housing's mesh (the projected line too, so the housing's element edges follow
it). Each such pair (card node c, housing node h) is joined through a twin node at c's place, tied
rigidly to h (translations u_h + theta_h x (x_c - x_h), rotations theta_h), to which c is held as the
fixture says:

- wedge-lock guide (thesis section 7.4): translations tied, the two rotations across the edge tied,
  the rotation about the edge through the guide's k_rot per unit length (an ``edge_joint`` set between
  the card's line of nodes and the twins', ``cards.<card>.fixtures.<name>``), or tied ("clamped") or
  free ("hinged"); a clamped edge ties all six DOFs, a hinged edge all but the rotation about it; a
  contact strip (``width``) moves rigidly with the housing node nearest along the line;
- standoff: a spring k (x, y, z) between the card's standoff centre and its twin, or the translations
  tied ("rigid").

Quantities of a card are the board's own under ``cards.<card>.`` (``cards.card1.components.U1.thickness``),
as are its element sets and named points.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from .. import targets
from ..board.model import build_model as build_card
from ..fe import EdgeSpringProperty, SpringProperty, dof_index
from ..fe.assembly import assemble
from ..fe.frames import idle_dofs, placed
from ..fe.parametric import SetMaker
from ..fe.probe import segment_parameter
from ..fixtures.supports import edge_nodes, edge_rotation
from .model import BoxModel, _tie_across, build_model


class Prefixed(Mapping):
    """The quantities ``q`` of a system as a card's own (keys without ``prefix``)."""

    def __init__(self, q: dict, prefix: str):
        self.q, self.prefix = q, prefix

    def __getitem__(self, key):
        return self.q[self.prefix + key]

    def __iter__(self):
        n = len(self.prefix)
        return (k[n:] for k in self.q if k.startswith(self.prefix))

    def __len__(self):
        return sum(1 for _ in self)


@dataclass
class PlacedCard:
    """A card in the system model: its own model ``local`` (board frame), and its nodes there are the
    system's nodes ``first`` .. ``first + local.model.n_nodes - 1``; ``interface``: the system nodes of
    the card that the housing holds; ``extra``: housing nodes on the card's lines that are no card
    node's (0 where the meshes conform node for node)."""

    card: object
    local: object
    first: int
    interface: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    extra: int = 0

    @property
    def nodes(self) -> np.ndarray:
        return self.first + np.arange(self.local.model.n_nodes)


@dataclass
class SystemModel(BoxModel):
    """The FE model of a box with its cards (a :class:`BoxModel` whose ``cards`` are {name: PlacedCard})."""

    cards: dict = field(default_factory=dict)

    def share_groups(self) -> dict:
        """The plates (ribs with their plate) and the cards, each one part of a mode's energy."""
        groups = super().share_groups()
        groups.update({name: [n for n in self.model.sets if n.startswith(targets.prefix("cards", name))] for name in self.cards})
        return groups

    def reduced_parts(self, modes: int | None = None) -> list:
        """[(global DOFs of a card, fixed-interface modes)] of the cards to reduce (Craig-Bampton):
        those whose entry asks for it, or every card with ``modes``."""
        return [(dof_index(pc.nodes).ravel(), modes or pc.card.reduce) for pc in self.cards.values()
                if modes or pc.card.reduce]

    def solve(self, n_modes: int | None = None, f_max: float | None = None, K=None, M=None, reduce: int | None = None):
        """The modes of the system (:func:`pcbdyn.fe.modal.solve_modes`), with the cards that ask for it
        (or all with ``reduce`` modes each) reduced to their interface (:mod:`pcbdyn.fe.craig_bampton`)."""
        from ..fe.craig_bampton import craig_bampton, solve_reduced
        from ..fe.modal import solve_modes

        parts = self.reduced_parts(reduce)
        if K is None or M is None:
            K, M = assemble(self.model)
        if not parts:
            return solve_modes(self.model, n_modes, f_max, K=K, M=M)
        return solve_reduced(craig_bampton(self.model, K, M, parts), n_modes, f_max, self.model.free)

    def reduction_error(self, modes, K, M) -> dict | None:
        """None when no card is reduced; else the error of the reduced ``modes`` against the full model's
        (solved here for as many modes): {"cards": {name: fixed-interface modes}, "errors_pct": per mode,
        "max_error_pct"}, the contract of ``build --json``'s "reduction"."""
        from ..fe.modal import solve_modes

        parts = {name: pc.card.reduce for name, pc in self.cards.items() if pc.card.reduce}
        if not parts:
            return None
        full = solve_modes(self.model, modes.frequencies.size, K=K, M=M).frequencies
        n = min(full.size, modes.frequencies.size)
        err = 100.0 * (modes.frequencies[:n] / full[:n] - 1.0)
        return {"cards": parts, "errors_pct": err.tolist(), "max_error_pct": float(np.abs(err).max(initial=0.0))}

    def layout_hints(self) -> tuple:
        suspects, footprints, t = super().layout_hints()
        return suspects, footprints, min([t] + [pc.card.board.thickness for pc in self.cards.values()])


def _project(plate, x) -> np.ndarray:
    """Points ``x`` (k, 3) projected on ``plate``'s mid-surface."""
    n = plate.normal
    return x - np.outer((x - plate.origin) @ n, n)


def _interfaces(box, card, local) -> list:
    """[(hold, card nodes (local numbers), strip nodes, housing points (k, 3))] of every fixture the
    housing holds."""
    out = []
    for hold in box.holds[card.name]:
        f, plate = hold.fixture, box.plate(hold.plate)
        if f.type == "standoff":
            c = np.array([local.point_nodes[targets.entry("fixtures", f.name)]])
            x = card.point(local.model.nodes[c])
            if hold.rib is not None:
                rib = box.rib(hold.rib)
                a, b = plate.point(*rib.start)[None], plate.point(*rib.end)[None]
                h = a + segment_parameter(x, a, b)[:, None] * (b - a)
            else:
                h = _project(plate, x)
            out.append((hold, c, np.zeros(0, dtype=np.int64), h))
            continue
        line, strip = edge_nodes(local.mesh, card.board.outline, f)
        out.append((hold, line, strip, _project(plate, card.point(local.mesh.nodes[line]))))
    return out


def _hold_point(card, i: int, k: int) -> str:
    """The name of housing point ``k`` of hold ``i`` of ``card`` (its interface with the housing)."""
    return targets.prefix("cards", card.name) + f"holds.{i}.{k}"


def _place(model, q, makers, point_nodes, card, local) -> PlacedCard:
    """Add card ``local`` (its BoardModel) to the system ``model`` in its frame; its quantities, makers
    and named points under ``cards.<name>.``."""
    prefix = targets.prefix("cards", card.name)
    first = model.n_nodes
    K, M = assemble(local.model)
    nodes, fixed, mpcs = placed(local.model, card.R, card.origin, first, idle_dofs(local.model, K, M))
    model.add_nodes(nodes)
    model.fixed |= fixed
    model.mpcs += mpcs
    q.update({prefix + k: v for k, v in local.quantities.items()})
    for name, mk in local.makers.items():
        makers[prefix + name] = SetMaker(mk.etype, np.asarray(mk.conn) + first, tuple(prefix + d for d in mk.deps),
                                         lambda q, mk=mk: mk.make(Prefixed(q, prefix)), card.R,
                                         {prefix + k: v for k, v in mk.powers.items()})
    point_nodes.update({prefix + k: int(v) + first for k, v in local.point_nodes.items()})
    return PlacedCard(card, local, first)


def _twins(model, c_nodes, h_nodes) -> np.ndarray:
    """Twin nodes at the card nodes' places, each tied rigidly to its housing node."""
    twins = model.add_nodes(model.nodes[c_nodes])
    for t, h in zip(twins, h_nodes):
        model.rigid_link(int(h), [int(t)])
    return twins


def _hold(model, q, makers, pc, hold, c_nodes, strip, h_nodes, taken: set) -> None:
    """Join card nodes ``c_nodes`` (system numbers) to housing nodes ``h_nodes`` as fixture
    ``hold.fixture`` says (see the module doc); ``taken``: card nodes already held by another fixture
    (a corner two fixtures share keeps the first one's ties)."""
    f = hold.fixture
    key = targets.prefix("cards", pc.card.name) + targets.entry("fixtures", f.name)
    free = np.array([int(c) not in taken for c in c_nodes])
    twins = _twins(model, c_nodes, h_nodes)
    for c, t in zip(c_nodes[free], twins[free]):
        for k in range(3):
            if f.type != "standoff" or f.k == "rigid":
                model.couple(int(dof_index(t)[k]), int(dof_index(c)[k]))
    taken.update(int(c) for c in c_nodes)
    if f.type == "standoff":
        if f.k != "rigid":
            k_key = targets.prefix("cards", pc.card.name) + targets.target("fixtures", f.name, "k")
            q[k_key] = float(f.k)
            makers[key] = SetMaker("spring", np.column_stack([c_nodes, twins]), (k_key,),
                                   lambda q, k=k_key: SpringProperty(k=(q[k], q[k], q[k], 0.0, 0.0, 0.0)))
        return
    rot = edge_rotation(f)
    e = model.nodes[c_nodes[-1]] - model.nodes[c_nodes[0]]
    e /= np.linalg.norm(e)
    for c, t in zip(c_nodes[free], twins[free]):
        if rot == "clamped":
            for k in range(3, 6):
                model.couple(int(dof_index(t)[k]), int(dof_index(c)[k]))
        else:
            _tie_across(model, int(c), int(t), e)
    if not isinstance(rot, str):
        k_key = targets.prefix("cards", pc.card.name) + targets.target("fixtures", f.name, "k_rot")
        q[k_key] = float(rot)
        cells = np.column_stack([c_nodes[:-1], c_nodes[1:], twins[:-1], twins[1:]])
        makers[key] = SetMaker("edge_joint", cells, (k_key,), lambda q, k=k_key, n=tuple(
            pc.card.normal): EdgeSpringProperty(k=(0.0, 0.0, 0.0, q[k], 0.0, 0.0), normal=n))
    along = (model.nodes[c_nodes] - model.nodes[c_nodes[0]]) @ e
    for s in strip:
        if int(s) not in taken:
            model.rigid_link(int(h_nodes[np.argmin(np.abs(along - (model.nodes[s] - model.nodes[c_nodes[0]]) @ e))]),
                             [int(s)])
            taken.add(int(s))


def _tie_between(model, line, h_nodes) -> int:
    """Tie each housing node of ``line`` (its nodes along a card's edge) that is no card node's partner
    (``h_nodes``) to the straight line between the two partners around it, in translation (the card's
    edge is straight between its nodes); returns how many there were. gmsh's split of a mesh into quads
    halves every edge, the embedded card nodes' too: then every other node along the line is tied."""
    x = model.nodes
    e = x[h_nodes[-1]] - x[h_nodes[0]]
    at = (x[h_nodes] - x[h_nodes[0]]) @ e / (e @ e)
    order = np.argsort(at)
    slaves = {s for s, _ in model.mpcs}
    extra = [int(n) for n in line if int(n) not in set(h_nodes.tolist())]
    for n in extra:
        s = (x[n] - x[h_nodes[0]]) @ e / (e @ e)
        i = int(np.clip(np.searchsorted(at[order], s), 1, len(order) - 1))
        a, b = h_nodes[order[i - 1]], h_nodes[order[i]]
        w = (s - at[order[i - 1]]) / (at[order[i]] - at[order[i - 1]])
        for k in range(3):
            d = int(dof_index(n)[k])
            if d not in slaves and d not in model.fixed:
                model.constrain(d, [(int(dof_index(a)[k]), 1.0 - w), (int(dof_index(b)[k]), w)])
    return len(extra)


def build_system(box, config: str | None = None, mesh_size: float | None = None,
                 shared_mesh: bool = False) -> SystemModel:
    """The FE model of ``box`` with its cards in configuration ``config`` (of the box); ``mesh_size``
    [m] replaces the box's, and scales each card's by the same factor (a finer model of everything)."""
    scale = (mesh_size or box.mesh_size) / box.mesh_size
    locals_, faces, points, lines = {}, {}, [], []
    for card in box.cards:
        local = build_card(card.board, None, card.board.mesh_size * scale, housed=True)
        locals_[card.name] = local
        faces[card.name] = _interfaces(box, card, local)
        for i, (hold, _, _, h) in enumerate(faces[card.name]):
            points += [(_hold_point(card, i, k), hold.plate, x) for k, x in enumerate(h)]
            if len(h) > 1:
                lines.append((h[0], h[-1]))
    bm = build_model(box, config, mesh_size, shared_mesh, points=points, lines=lines, bind=False)
    model, q, makers = bm.model, dict(bm.quantities), {}
    point_nodes = {k: v for k, v in bm.point_nodes.items() if not k.startswith("cards.")}
    placed_cards = {}
    for card in box.cards:
        pc = _place(model, q, makers, point_nodes, card, locals_[card.name])
        taken: set = set()
        for i, (hold, c, strip, h) in enumerate(faces[card.name]):
            h_nodes = np.array([bm.point_nodes[_hold_point(card, i, k)] for k in range(len(h))])
            _hold(model, q, makers, pc, hold, c + pc.first, strip + pc.first, h_nodes, taken)
            pc.interface = np.union1d(pc.interface, c + pc.first)
            if len(h) > 1:
                pc.extra += _tie_between(model, bm.plate_map[hold.plate][bm.mesh.chain(
                    h[0], h[-1], bm.mesh.plate_nodes(hold.plate))], h_nodes)
        placed_cards[card.name] = pc
    for name, mk in makers.items():
        model.add(name, mk.etype, mk.conn, mk.make(q), mk.frame)
    model.node_groups.update({name: np.array([n]) for name, n in point_nodes.items()})
    sm = SystemModel(model, q, {**bm.makers, **makers}, point_nodes=point_nodes, box=box, mesh=bm.mesh,
                     configuration=config, plate_map=bm.plate_map, cards=placed_cards)
    sm.bind(box.parameters)
    return sm
