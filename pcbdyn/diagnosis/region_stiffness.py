"""``region_stiffness``: a relative change s (dimensionless) of the membrane, bending and shear
stiffness of the shells in a region (a local thickness or modulus error, a part stiffening the
board, a delamination when s < 0). The region's element stiffness becomes (1 + s) K_e and its mass is
unchanged, so K is linear in s with dK/ds = the region's element stiffness, dM/ds = 0.
A thickness change dt corresponds to s of about 3 dt / t in bending.

A candidate holds its cells (node rows), not their properties: dK/ds and the added effect use the
properties the cells have in the model they are applied to, so a region effect follows the
declared parameters (board E, part thickness) when both are estimated together, and overlapping
region effects add up.

Candidates: a grid of square patches of side ``patch`` [m], grids of twice that side (aligned and
shifted by half a patch, so that a larger region is met by one candidate of about its size) and
every part footprint. On a structure in 3-D (a box) the footprints are its plates: a plate stiffer or
softer than declared as a whole (its E, its thickness), reported with the plate's name.
"""

from __future__ import annotations

import numpy as np
import shapely

from .. import targets
from ..board.effects import ScaledShell
from ..fe.elements import kernel
from .catalogue import register, Blocks, Candidate


def _area_centroid(conns, xy) -> tuple:
    """(area, area centroid) of a set of polygonal cells (shoelace formula per cell; in 3-D, ``xy``
    (n, 3), triangle fans of planar cells)."""
    if xy.shape[1] == 3:
        area, moment = 0.0, np.zeros(3)
        for c in conns:
            p = xy[c]
            for k in range(1, c.shape[1] - 1):
                a = 0.5 * np.linalg.norm(np.cross(p[:, k] - p[:, 0], p[:, k + 1] - p[:, 0]), axis=1)
                area += a.sum()
                moment += a @ ((p[:, 0] + p[:, k] + p[:, k + 1]) / 3.0)
        return area, moment / area
    area, moment = 0.0, np.zeros(2)
    for c in conns:
        p, q = xy[c], xy[np.roll(c, -1, axis=1)]
        cross = p[..., 0] * q[..., 1] - q[..., 0] * p[..., 1]
        area += cross.sum() / 2.0
        moment += np.einsum("cv,cvk->k", cross, p + q) / 6.0
    return area, moment / area


def _candidate(layout, label: str, polygon, name: str = "region_stiffness") -> Candidate | None:
    """A candidate of kind ``name`` on the shell cells whose centroid is in ``polygon`` (``data["cells"]``:
    {etype: conn}; ``data["area"]``: theirs [m^2])."""
    sets = layout.model.sets
    found: dict = {}
    for n, i in layout.cells_in(polygon):
        found.setdefault(sets[n].etype, []).append(sets[n].conn[i])
    if not found:
        return None
    cells = {etype: np.concatenate(c) for etype, c in found.items()}
    nodes = np.unique(np.concatenate([c.ravel() for c in cells.values()]))
    plate = label.removeprefix("plates.") if label.startswith("plates.") and layout.plates else None
    area, centroid = _area_centroid(list(cells.values()), layout.points)
    return Candidate(name, f"{name}@{label}", tuple(centroid), nodes,
                     {"polygon": np.asarray(polygon, dtype=float)},
                     {"cells": cells, "area": float(area), **({"plate": plate} if plate else {})})


def _rows(a: np.ndarray) -> np.ndarray:
    """Rows of an integer array as single comparable items."""
    a = np.ascontiguousarray(a, dtype=np.int64)
    return a.view(np.dtype((np.void, a.dtype.itemsize * a.shape[1]))).ravel()


def _base(prop):
    """(base property, present stiffness factor) of a set's property."""
    return (prop.base, prop.factor) if isinstance(prop, ScaledShell) else (prop, 1.0)


def _locate(model, etype: str, conn: np.ndarray):
    """[(set name, mask over the set's cells, mask over ``conn``)] for the sets holding rows of ``conn``."""
    keys = _rows(conn)
    out, found = [], np.zeros(len(conn), dtype=bool)
    for name, es in model.sets.items():
        if es.etype != etype or not len(es.conn):
            continue
        rows = _rows(es.conn)
        in_set = np.isin(rows, keys)
        if in_set.any():
            mine = np.isin(keys, rows[in_set])
            found |= mine
            out.append((name, in_set, mine))
    if not found.all():
        raise ValueError(f"{len(conn) - found.sum()} cells of a region are not in the model; "
                         "generate the candidates on this model's mesh")
    return out


class _RegionStiffness:
    name = report_as = "region_stiffness"
    uses_properties = True  # dK/ds is the region's own stiffness, which the declared parameters move
    param = "stiffness_change"
    unit = "1"
    scale = 0.3
    lower = -0.9
    options = ("patch",)
    together = ("region_mass",)  # a body glued over the region (a heat sink) brings both
    coarse = True  # patches of 20 and 40 mm: a refused region is walked before it is refused (:mod:`.select`)

    def generate(self, layout, patch: float = 0.02) -> list:
        if not patch > 0:
            raise ValueError(f"patch must be > 0 m, got {patch}")
        if not layout.planar:  # a box: its plates
            found = (_candidate(layout, label, poly, self.name) for label, poly in layout.footprints.items())
            return [c for c in found if c is not None]
        xy = layout.xy[layout.shell_nodes()]
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        polys = []
        for tag, size, shift in (("", patch, 0.0), ("2x", 2 * patch, 0.0), ("2x+", 2 * patch, 0.5)):
            n = np.maximum(1, np.round((hi - lo) / size)).astype(int)
            step = (hi - lo) / n
            # shifted patches are cut at the plate's edges (an enriched board holds its regions inside the outline)
            gx = np.clip(lo[0] + step[0] * (np.arange(n[0] + 1 + (shift > 0)) - shift), lo[0], hi[0])
            gy = np.clip(lo[1] + step[1] * (np.arange(n[1] + 1 + (shift > 0)) - shift), lo[1], hi[1])
            polys += [(f"patch{tag}[{i},{j}]", [[gx[i], gy[j]], [gx[i + 1], gy[j]], [gx[i + 1], gy[j + 1]],
                                                [gx[i], gy[j + 1]]])
                      for j in range(gy.size - 1) for i in range(gx.size - 1)]
        polys += list(layout.footprints.items())
        return [c for label, poly in polys if (c := _candidate(layout, label, poly, self.name)) is not None]

    def joint(self, candidates):
        """A test ``ok(values)`` of the changes taken together: where regions overlap their changes
        add, so each region's change plus every softening of a region over it must stay at or above
        ``lower`` (overlap by area, not by this mesh's cells: two regions that share no cell here may
        share cells of a finer mesh, where a summed factor <= 0 made K indefinite)."""
        over = [[j for j, b in enumerate(candidates) if j != i and _overlap(a, b)] for i, a in enumerate(candidates)]

        def ok(values) -> bool:
            v = np.asarray(values, float)
            return all(v[i] + np.minimum(v[o], 0.0).sum() >= self.lower for i, o in enumerate(over))

        return ok

    @staticmethod
    def moved_value(old, new, value: float) -> float:
        """The change a region moved from ``old`` to ``new`` (a step of the local search) starts from:
        the one that keeps the change's integral over the board, ``value`` times the ratio of their
        cells' areas. The data fix that integral better than either factor, and a stiffening kept at
        its value while the region grows is far too stiff for the few steps of a trial fit to come
        back from (a 4 x 4 element region 1.3 stiffer, found first over 2 x 2 elements: walked with
        its change held, the search stopped over 2 x 4 at 4.3, chi^2 66 against 4 at the truth)."""
        return value * old.data["area"] / new.data["area"]

    def candidate(self, layout, label: str, polygon):
        """The region over ``polygon`` [[x, y], ...] [m] (None where it holds no cell centroid)."""
        return _candidate(layout, label, polygon, self.name)

    def place(self, layout, candidate):
        """Over ``candidate``'s polygon (ValueError where it holds no cell centroid)."""
        plate = candidate.data.get("plate")
        c = _candidate(layout, targets.entry("plates", plate) if plate else "placed",
                       candidate.geometry["polygon"], self.name)
        if c is None:
            raise ValueError(f"{candidate.name}: its polygon holds no cell")
        return c

    def rectangle(self, layout, x0: float, y0: float, x1: float, y1: float):
        """The region over the rectangle [x0, x1] x [y0, y1] [m], named by its corners in mm."""
        label = "rect[" + ",".join(f"{1e3 * v:.4g}" for v in (x0, y0, x1, y1)) + "]mm"
        return _candidate(layout, label, [[x0, y0], [x1, y0], [x1, y1], [x0, y1]], self.name)

    def blocks(self, model, candidates) -> list:
        """Element stiffness of the regions' cells with their base properties in ``model``; one
        kernel call per (element type, property) over all candidates."""
        out = []
        for etype in {e for c in candidates for e in c.data["cells"]}:
            parts = [(k, c.data["cells"][etype]) for k, c in enumerate(candidates) if etype in c.data["cells"]]
            conn = np.concatenate([c for _, c in parts])
            owner = np.repeat([k for k, _ in parts], [len(c) for _, c in parts])
            for name, _, mine in _locate(model, etype, conn):
                Ke, _ = kernel(etype)(model.nodes[conn[mine]], _base(model.sets[name].prop)[0])
                out.append(Blocks(conn[mine], Ke, np.zeros_like(Ke), owner[mine]))
        return out

    def apply(self, model, candidate, value: float):
        """The region's cells move out of their sets into ``effects.<name>...`` sets whose stiffness
        is (f + value) times that of their base property, f being their present factor (1, or that
        of an overlapping region effect added before); f + value must stay > 0."""
        m = model.copy()
        for etype, conn in candidate.data["cells"].items():
            for name, in_set, _ in _locate(m, etype, conn):
                es = m.sets[name]
                base, f = _base(es.prop)
                if not f + value > 0.0:
                    raise ValueError(f"{candidate.name}: a stiffness change must leave the stiffness > 0 "
                                     f"(change > {-f:g}), got {value}")
                if in_set.all():
                    del m.sets[name]
                else:
                    m.sets[name] = type(es)(es.name, es.etype, es.conn[~in_set], es.prop)
                m.add(_fresh(m, f"effects.{candidate.name}.{name}"), etype, es.conn[in_set], ScaledShell(base, f + value))
        return m


def _overlap(a, b) -> bool:
    """Whether regions ``a`` and ``b`` share area: a box's plates when they are one plate, a board's
    regions by their polygons."""
    if a.data.get("plate") or b.data.get("plate"):
        return a.data.get("plate") == b.data.get("plate")
    pa, pb = (shapely.Polygon(c.geometry["polygon"]) for c in (a, b))
    return pa.intersection(pb).area > 1e-9 * min(pa.area, pb.area)


def _fresh(model, name: str) -> str:
    """``name``, or ``name#k`` when a set of that name exists."""
    k, out = 1, name
    while out in model.sets:
        out, k = f"{name}#{k}", k + 1
    return out


KIND = _RegionStiffness()
register(KIND)
