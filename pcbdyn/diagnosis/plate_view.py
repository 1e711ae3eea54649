"""One plate of a structure in 3-D (a housing's wall) seen in its own plane: the kinds whose candidates
are lines across a plate (:mod:`.stiffener`) place them on each plate as they do on a board, then lift
them into space. The view keeps the structure's node numbers, so the cells a line crosses and their
shape-function weights apply to the structure's own model."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np


@dataclass(frozen=True)
class Frame:
    """A plate's plane: ``origin`` (3,) [m], in-plane unit ``axes`` (2, 3) and the unit ``normal`` (3,) =
    axes[0] x axes[1], which points to the side of the structure's centre (a housing's inside)."""

    origin: np.ndarray
    axes: np.ndarray
    normal: np.ndarray

    def flat(self, xyz) -> np.ndarray:
        """Plane coordinates (..., 2) [m] of points ``xyz`` (..., 3)."""
        return (np.asarray(xyz, float) - self.origin) @ self.axes.T

    def lift(self, st) -> np.ndarray:
        """Points (..., 3) [m] of plane coordinates ``st`` (..., 2)."""
        return self.origin + np.asarray(st, float) @ self.axes


def plate_view(layout, name: str) -> tuple:
    """(the :class:`.layout.Layout` of plate ``name`` of ``layout.plates`` in its plane, its
    :class:`Frame`). The plane's axes are the global ones least along the normal (a wall x = const is
    seen in y, z), its origin the plate's lowest corner, so that names read as plate coordinates; only
    the cells whose every node is on the plate are in the view (not the neighbours' cells along a
    shared edge)."""
    from .layout import _thickness, from_model

    nodes = np.asarray(layout.plates[name], dtype=np.int64)
    xyz = layout.model.nodes
    mine = np.zeros(len(xyz), bool)
    mine[nodes] = True
    sets = {}
    for set_name, conn in layout.cells():
        own = conn[mine[conn].all(axis=1)]
        if len(own):
            s = layout.model.sets[set_name]
            sets[set_name] = SimpleNamespace(etype=s.etype, conn=own, prop=s.prop)
    if not sets:
        raise ValueError(f"plate {name!r} has no shell cells of its own")
    p = xyz[nodes]
    centre = p.mean(axis=0)
    n = np.linalg.svd(p - centre)[2][2]
    if n @ (xyz[layout.shell_nodes()].mean(axis=0) - centre) < 0:
        n = -n
    e1 = np.eye(3)[np.sort(np.argsort(np.abs(n))[:2])[0]]
    e1 = e1 - (e1 @ n) * n
    e1 /= np.linalg.norm(e1)
    axes = np.array([e1, np.cross(n, e1)])
    origin = centre + ((p - centre) @ axes.T).min(axis=0) @ axes
    frame = Frame(origin, axes, n)
    flat = xyz.copy()
    flat[nodes] = np.column_stack([frame.flat(p), np.zeros(len(p))])
    view = from_model(SimpleNamespace(nodes=flat, sets=sets), thickness=_thickness(next(iter(sets.values())).prop))
    return view, frame
