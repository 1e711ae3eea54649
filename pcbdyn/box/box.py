"""A box (a ribbed shell housing: plates in 3-D with ribs, joints, supports and point masses): its
validated description and the domain-model interface (:mod:`pcbdyn.domain`) that the bridge to updating
and diagnosis uses, as a board's: the quantities parameter targets address, the FE model of a
configuration, measurement points on the plates, the updated box.toml."""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import tomlkit

from .. import targets
from ..atomic import write_checked
from ..board import load_board
from ..inputs import MAX_ENTRIES, MAX_NAME, Reader, read_toml
from ..domain import Analysis, Configured
from .cards import MAX_CARDS, holds, read_card
from .entries import MAX_PLATES, RIB_MODELS, BoxError
from .enrich import enriched_text
from .model import BoxModel, build_model
from .spec import (check_plates, read_configuration, read_joint, read_mass, read_materials, read_plate, read_rib,
                   read_support)

#: the collections of box.toml that parameter targets address (``cards``: a card's own targets under
#: ``cards.<card>.``, e.g. ``cards.card1.components.U1.thickness``)
COLLECTIONS = ("plates", "ribs", "joints", "masses", "cards")
#: [m] how far a measurement point may lie from the nearest plate's mid-surface (points on a face, on
#: a rib's flank); farther ones are an error that names them
POINT_TOL = 0.005


@dataclass
class Box(Configured):
    name: str
    path: Path
    plates: list
    mesh_size: float
    rib_model: str  # "beam" (eccentric beams) or "shell" (shell strips: the check model)
    contacts: list = field(default_factory=list)
    ribs: list = field(default_factory=list)
    supports: list = field(default_factory=list)
    joints: list = field(default_factory=list)
    masses: list = field(default_factory=list)
    configurations: list = field(default_factory=list)
    parameters: list = field(default_factory=list)
    analysis: Analysis = field(default_factory=Analysis)
    cards: list = field(default_factory=list)  # .cards.Card
    holds: dict = field(default_factory=dict)  # {card name: [.cards.Hold]}
    guides: list = field(default_factory=list)  # lines (m, 3) [m] element edges also follow (:meth:`following`)

    def card(self, name):
        return next((c for c in self.cards if c.name == name), None)

    def plate(self, name):
        return next((p for p in self.plates if p.name == name), None)

    def rib(self, name):
        return next((r for r in self.ribs if r.name == name), None)

    def quantity(self, target: str) -> float | None:
        """The current value [SI] of a parameter target such as ``plates.upper.E``; None when the box has
        no such quantity (an orthotropic plate's E, a shell-strip rib's height)."""
        try:
            t = targets.parse(target, COLLECTIONS)
        except targets.TargetError:
            return None
        if t.prefix is not None:
            card = self.card(t.prefix.split(".", 1)[1])
            return None if card is None else card.board.quantity(str(t).split(".", 2)[2])
        if t.collection == "plates" and (p := self.plate(t.name)) is not None:
            if t.attribute == "E":
                return None if p.material.orthotropic else p.material.E
            return {"rho": p.material.rho, "thickness": p.thickness}.get(t.attribute)
        if t.collection == "ribs" and (r := self.rib(t.name)) is not None and self.rib_model == "beam":
            return getattr(r, t.attribute, None)
        if t.collection == "joints" and (j := next((j for j in self.joints if j.name == t.name), None)) is not None:
            return j.k_rot if t.attribute == "k_rot" else None
        if t.collection == "masses" and (m := next((m for m in self.masses if m.name == t.name), None)) is not None:
            return m.mass if t.attribute == "mass" else None
        return None

    # -------------------------------------------------------------------- domain-model interface
    def build(self, config: str | None = None, mesh_size: float | None = None, shared_mesh: bool = False) -> BoxModel:
        """The FE model of configuration ``config`` (None: the base one); see :func:`.model.build_model`,
        and with cards :func:`.system.build_system`."""
        if self.cards:
            from .system import build_system

            return build_system(self, config, mesh_size, shared_mesh)
        return build_model(self, config, mesh_size, shared_mesh)

    def following(self, lines) -> "Box":
        """This box meshed so that element edges also follow ``lines`` (polylines (m, 3) [m] on its plates)
        with nothing declared on them: where a diagnosis found ribs (:mod:`pcbdyn.diagnosis.conforming`)."""
        return replace(self, guides=[np.asarray(line, float) for line in lines])

    def nearest_plates(self, xyz) -> tuple:
        """(index of the nearest plate, distance [m]) of each point (k, 3)."""
        d = np.array([p.distance(xyz) for p in self.plates])
        return d.argmin(axis=0), d.min(axis=0)

    def nearest_part(self, xyz) -> tuple:
        """(index of the nearest plate or card (cards after the plates), distance [m]) of each point (k, 3)."""
        d = np.array([p.distance(xyz) for p in self.plates] + [c.distance(xyz) for c in self.cards])
        return d.argmin(axis=0), d.min(axis=0)

    def check_points(self, points, source) -> None:
        """A BoxError naming the points (``points.ids``, ``points.xyz`` [m]) of ``source`` farther than
        :data:`POINT_TOL` from every plate, with the nearest plate and how far it is."""
        near, dist = self.nearest_part(points.xyz)
        off = dist > POINT_TOL
        if off.any():
            names = [f"plate '{p.name}'" for p in self.plates] + [f"card '{c.name}'" for c in self.cards]
            listed = "; ".join(f"{int(i)} at {np.round(x * 1e3, 3).tolist()} mm is {d * 1e3:.3g} mm from {names[k]}"
                               for i, x, d, k in zip(points.ids[off][:10], points.xyz[off][:10], dist[off][:10],
                                                     near[off][:10]))
            raise BoxError(f"{Path(source).name}: {int(off.sum())} point(s) lie off every plate{' and card' if self.cards else ''} of {self.path.name} "
                           f"(more than {POINT_TOL * 1e3:g} mm away): {listed}{' ...' if off.sum() > 10 else ''}. "
                           "Give the points in the box frame of the file and state their unit in the header (e.g. "
                           "'x [mm]')")

    def outlines(self, config: str | None = None) -> list:
        """What a 3-D mode-shape picture outlines, as plain data: ``{"kind", "label", "xyz": [[x, y, z],
        ...] in metres, "closed"}`` for the plates, ribs, supported edges, point masses (a single point
        is a marker)."""
        def item(kind, label, pts, closed=False):
            return {"kind": kind, "label": label, "xyz": np.asarray(pts, float).reshape(-1, 3).tolist(),
                    "closed": closed}

        items = [item("plate", p.name, p.corners(), True) for p in self.plates]
        items += [item("stiffener", r.name, [self.plate(r.plate).point(*r.start), self.plate(r.plate).point(*r.end)])
                  for r in self.ribs]
        items += [item("fixture", f"{s.type} {s.plate}.{s.edge}", self.plate(s.plate).edge(s.edge))
                  for s in self.supports]
        items += [item("plate", c.name, c.point(c.board.outline.vertices), True) for c in self.cards]
        added = self.configuration(config).masses if config else []
        items += [item("mass", m.name + (f" ({config})" if m in added else ""), [self.plate(m.plate).point(*m.at)])
                  for m in self.masses + added]
        return items

    def write_enriched(self, effects, dst, values: dict | None = None) -> Path:
        """``dst``: this box.toml with the effects a diagnosis found declared (:mod:`.enrich`) and the
        parameters' fitted ``values`` {name: SI} written into their targets (as :meth:`write_updated`
        does), so that it builds the diagnosed model; written atomically once it loads. An effect that
        scales a plate's modulus scales the fitted one."""
        text = self._updated_text(values or {}, dst, "pcbdyn diagnose")
        fitted = parse_box(tomlkit.parse(text).unwrap(), Path(dst)) if values else self
        return write_checked(dst, enriched_text(fitted, text, effects), load_box, BoxError)

    def write_updated(self, values: dict, dst, source: str = "pcbdyn update") -> Path:
        """``dst``: this box.toml with the parameters' ``values`` {name: SI} written into their targets
        (comments and layout kept), checked by loading it before it replaces ``dst``. A card's targets go
        to an updated copy of its board.toml, written beside it and named as ``dst`` is after the box
        (box.updated.2.toml: card1.updated.2.toml), which the updated box then names."""
        return write_checked(dst, self._updated_text(values, dst, source), load_box, BoxError)

    def _updated_text(self, values: dict, dst, source: str) -> str:
        """The box.toml text of :meth:`write_updated` for ``dst`` (its cards named relative to it), the
        cards' updated copies written."""
        assignments = targets.assignments(self.parameters, values)
        dst = Path(dst)
        tail = dst.name[len(self.path.stem):] if dst.name.startswith(self.path.stem) else f".{dst.name}"
        doc = tomlkit.parse(self.path.read_text(encoding="utf-8"))
        for i, card in enumerate(self.cards):
            own = {t.split(".", 2)[2]: v for t, v in assignments.items() if t.startswith(targets.prefix("cards", card.name))}
            path = board = card.board.path
            if own:
                path = board.with_name(board.stem + tail)
                text = targets.updated_text(board.read_text(encoding="utf-8"), own)
                write_checked(path, f"# {board.name} in {dst.name}, with {', '.join(own)} updated by {source}\n"
                              + text, load_board, BoxError)
            doc["cards"][i]["board"] = os.path.relpath(path.resolve(), dst.resolve().parent).replace(os.sep, "/")
        text = targets.updated_text(tomlkit.dumps(doc), {t: v for t, v in assignments.items()
                                                        if not t.startswith("cards.")})
        return (f"# {self.path.name} with {', '.join(values)} updated by {source}\n" if values else "") + text


def load_box(path) -> Box:
    """Read and validate a box.toml."""
    return parse_box(read_toml(path, BoxError)[1], Path(path))


def _named(r, data, key, read, *args, limit: int = MAX_ENTRIES) -> list:
    """The entries of array ``key`` (at most ``limit``), each read by ``read(r, entry, where, name, *args)``,
    names unique."""
    out = [read(r, e, f"{key}[{i}]", r.name(key, e, i, f"{key}[{i}]"), *args)
           for i, e in enumerate(r.list(data, key, limit=limit))]
    r.unique([e.name for e in out], key, "name")
    return out


def parse_box(data: dict, path: Path) -> Box:
    """The Box of parsed box.toml ``data`` read from ``path``; a BoxError names the first bad field."""
    r = Reader(path, BoxError)
    r.table(data, "top level", ["box", "materials", "plates", "ribs", "supports", "joints", "masses",
                                "configurations", "parameters", "analysis", "cards"], required=["box", "plates"])
    b = r.table(data["box"], "box", ["name", "mesh_size", "rib_model"])
    rib_model = r.choice(b.get("rib_model", "beam"), "box.rib_model", RIB_MODELS, "rib model",
                         {"beam": "eccentric beams", "shell": "shell strips"})
    materials = read_materials(r, data)
    plates = _named(r, data, "plates", read_plate, materials, limit=MAX_PLATES)
    if not plates:
        r.fail("plates", "is empty; add [[plates]] with origin, u, v, thickness and material")
    box = Box(name=r.text(b["name"], "box.name", MAX_NAME) if "name" in b else Path(path).parent.name, path=Path(path), plates=plates,
              mesh_size=r.q(b.get("mesh_size", "10 mm"), "mm", "box.mesh_size", positive=True), rib_model=rib_model)
    box.ribs = _named(r, data, "ribs", read_rib, plates, materials)
    box.supports = [read_support(r, e, f"supports[{i}]", plates) for i, e in enumerate(r.list(data, "supports"))]
    box.contacts = check_plates(r, plates, box.supports)
    box.joints = _named(r, data, "joints", read_joint, box.contacts)
    box.masses = _named(r, data, "masses", read_mass, plates)
    box.configurations = [read_configuration(r, e, f"configurations[{i}]", plates)
                          for i, e in enumerate(r.list(data, "configurations"))]
    r.unique([c.name for c in box.configurations], "configurations", "name")
    box.analysis = r.analysis(data)
    box.cards = _named(r, data, "cards", read_card, path, limit=MAX_CARDS)
    box.holds = {c.name: holds(r, box, c, f"cards[{i}]") for i, c in enumerate(box.cards)}
    box.parameters = targets.read_parameters(r, data, box.quantity, COLLECTIONS)
    return box
