"""A KiCad board (.kicad_pcb, KiCad 6-8, read with kiutils) as plain data in the board frame:
Edge.Cuts loops (outline and cut-outs), the stack-up, and every footprint with its placement.

The board frame is pcbdyn's: metres, y up, origin at the lower-left corner of the outline's
bounding box. KiCad's y runs down and angles are counter-clockwise on screen, so a point
(x, y) maps to (x - x_min, y_max - y) and an angle keeps its value. A footprint's body is the
bounding box of its courtyard (else its fabrication outline, else its pads) in its own frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

MM = 1e-3
#: largest angle [deg] of one straight piece of an Edge.Cuts arc or circle
ARC_STEP = 10.0


class KicadError(ValueError):
    """A board file that cannot be imported, with the file, the item and the fix."""


@dataclass
class Footprint:
    ref: str
    lib_id: str
    at: tuple  # body centre (x, y) [m], board frame
    rotation: float  # [deg], counter-clockwise
    size: tuple  # body (a, b) [m] in the footprint's own axes
    side: str  # "top" or "bottom"
    hole: float = 0.0  # largest drill [m]
    pad: float = 0.0  # largest pad [m]


@dataclass
class Layout:
    name: str
    outline: np.ndarray  # (n, 2) [m]
    holes: list  # [("circle", centre (2,), diameter) | ("polygon", (m, 2))]
    stackup: list  # [(KiCad type, material or None, thickness [m])], top to bottom
    thickness: float  # [m]
    footprints: list = field(default_factory=list)


def _xy(p) -> np.ndarray:
    return np.array([float(p.X), float(p.Y)])


def _arc(start, mid, end) -> np.ndarray:
    """Points along the circular arc through start, mid, end (KiCad 6+ arcs), ends included."""
    (ax, ay), (bx, by), (cx, cy) = start, mid, end
    d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    if abs(d) < 1e-12:
        return np.array([start, end])
    ux = ((ax**2 + ay**2) * (by - cy) + (bx**2 + by**2) * (cy - ay) + (cx**2 + cy**2) * (ay - by)) / d
    uy = ((ax**2 + ay**2) * (cx - bx) + (bx**2 + by**2) * (ax - cx) + (cx**2 + cy**2) * (bx - ax)) / d
    centre = np.array([ux, uy])
    a0, a1, a2 = (math.atan2(p[1] - uy, p[0] - ux) for p in (start, mid, end))
    sweep = (a2 - a0) % (2 * math.pi)
    if (a1 - a0) % (2 * math.pi) > sweep:  # the arc runs the other way round
        sweep -= 2 * math.pi
    n = max(2, int(math.ceil(abs(math.degrees(sweep)) / ARC_STEP)))
    ang = a0 + sweep * np.linspace(0.0, 1.0, n + 1)
    r = np.linalg.norm(np.asarray(start) - centre)
    pts = centre + r * np.c_[np.cos(ang), np.sin(ang)]
    pts[0], pts[-1] = start, end
    return pts


def _edge_pieces(items):
    """Open pieces (polylines) and closed loops of the Edge.Cuts items, in KiCad mm."""
    pieces, loops = [], []
    for g in items:
        kind = type(g).__name__
        if kind == "GrLine":
            pieces.append(np.array([_xy(g.start), _xy(g.end)]))
        elif kind == "GrArc":
            pieces.append(_arc(_xy(g.start), _xy(g.mid), _xy(g.end)))
        elif kind == "GrRect":
            (x0, y0), (x1, y1) = _xy(g.start), _xy(g.end)
            loops.append(("polygon", np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])))
        elif kind == "GrPoly":
            loops.append(("polygon", np.array([_xy(p) for p in g.coordinates])))
        elif kind == "GrCircle":
            c = _xy(g.center)
            loops.append(("circle", c, 2.0 * float(np.linalg.norm(_xy(g.end) - c))))
        else:
            raise KicadError(f"Edge.Cuts item {kind} is not supported; draw the outline with lines, arcs, "
                             "rectangles, polygons or circles")
    return pieces, loops


def _chain(pieces, tol=1e-3) -> list:
    """Closed polylines from pieces that meet end to end (within ``tol`` mm)."""
    loops, left = [], list(pieces)
    while left:
        chain = [left.pop(0)]
        while np.linalg.norm(chain[-1][-1] - chain[0][0]) > tol:
            end = chain[-1][-1]
            for k, p in enumerate(left):
                if np.linalg.norm(p[0] - end) <= tol:
                    chain.append(left.pop(k))
                    break
                if np.linalg.norm(p[-1] - end) <= tol:
                    chain.append(left.pop(k)[::-1])
                    break
            else:
                raise KicadError(f"the Edge.Cuts lines do not close: an open end at ({end[0]:g}, {end[1]:g}) mm; "
                                 "join the outline in KiCad (Inspect > Board Setup checks, or DRC)")
        pts = np.vstack([c[:-1] for c in chain])
        loops.append(("polygon", pts))
    return loops


def _area(v) -> float:
    x, y = v[:, 0], v[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _body(fp):
    """(centre, (a, b)) of the footprint's body in its own frame [mm]: courtyard, fab or pads."""
    side = "B." if fp.layer.startswith("B.") else "F."
    for layer in ("CrtYd", "Fab"):
        pts = []
        for g in fp.graphicItems:
            if getattr(g, "layer", None) != side + layer:
                continue
            for key in ("start", "end", "mid", "center"):
                if getattr(g, key, None) is not None:
                    pts.append(_xy(getattr(g, key)))
            pts += [_xy(p) for p in getattr(g, "coordinates", []) or []]
            if type(g).__name__ == "FpCircle":
                c, r = _xy(g.center), float(np.linalg.norm(_xy(g.end) - _xy(g.center)))
                pts += [c - r, c + r]
        if len(pts) >= 2:
            p = np.array(pts)
            return 0.5 * (p.min(axis=0) + p.max(axis=0)), tuple(p.max(axis=0) - p.min(axis=0))
    if fp.pads:
        lo = np.min([_xy(p.position) - 0.5 * _xy(p.size) for p in fp.pads], axis=0)
        hi = np.max([_xy(p.position) + 0.5 * _xy(p.size) for p in fp.pads], axis=0)
        return 0.5 * (lo + hi), tuple(hi - lo)
    return np.zeros(2), (0.0, 0.0)


def _reference(fp) -> str:
    ref = fp.properties.get("Reference")
    if ref is None:
        ref = next((g.text for g in fp.graphicItems if type(g).__name__ == "FpText" and g.type == "reference"), "")
    return str(ref)


def read_kicad(path) -> Layout:
    """The layout of a .kicad_pcb file; a KicadError naming the file for anything unreadable."""
    from pathlib import Path

    from kiutils.board import Board

    path = Path(path)
    try:
        pcb = Board.from_file(str(path))
    except Exception as exc:  # kiutils raises bare Exceptions on malformed S-expressions
        raise KicadError(f"{path}: not a readable KiCad board ({type(exc).__name__}: {exc}); open and save it in "
                         "KiCad 6-8, or check that the file is a .kicad_pcb") from None
    try:
        return _layout(pcb, path)
    except KicadError:
        raise
    except (AttributeError, TypeError, ValueError, IndexError, KeyError, ZeroDivisionError) as exc:
        # kiutils reads some malformed boards without a word and leaves fields None or text
        raise KicadError(f"{path}: not a usable KiCad board ({type(exc).__name__}: {str(exc)[:200]}); open and save "
                         "it in KiCad 6-8") from None


def _layout(pcb, path) -> Layout:
    """The layout of a board kiutils read from ``path``."""
    try:
        pieces, loops = _edge_pieces([g for g in pcb.graphicItems if getattr(g, "layer", None) == "Edge.Cuts"])
        loops += _chain(pieces)
    except KicadError as exc:
        raise KicadError(f"{path}: Edge.Cuts: {exc}") from None
    polys = [lp for lp in loops if lp[0] == "polygon"]
    if not polys:
        raise KicadError(f"{path}: no closed board outline on the Edge.Cuts layer; draw the board's edge there")
    outer = max(polys, key=lambda lp: _area(lp[1]))[1]
    if not np.isfinite(outer).all():
        raise KicadError(f"{path}: the board outline on Edge.Cuts has coordinates that are not finite numbers")
    xmin, ymax = outer[:, 0].min(), outer[:, 1].max()

    def board(p) -> np.ndarray:
        """KiCad mm -> board frame m, for one point (2,) or many (n, 2)."""
        q = np.atleast_2d(np.asarray(p, float))
        out = np.column_stack([q[:, 0] - xmin, ymax - q[:, 1]]) * MM
        return out if np.ndim(p) > 1 else out[0]

    holes = []
    for lp in loops:
        if lp[0] == "circle":
            holes.append(("circle", board(lp[1]), lp[2] * MM))
        elif lp[1] is not outer:
            holes.append(("polygon", board(lp[1])))
    layers = []
    stack = pcb.setup.stackup.layers if pcb.setup.stackup is not None else []
    for L in stack:
        for sub in [L] + list(L.subLayers or []):
            if sub.thickness:
                layers.append((str(L.type), sub.material, float(sub.thickness) * MM))
    thickness = float(pcb.general.thickness) * MM
    title = pcb.titleBlock.title if pcb.titleBlock is not None and pcb.titleBlock.title else path.stem
    layout = Layout(title, board(outer), holes, layers, thickness)
    for fp in pcb.footprints:
        centre, (a, b) = _body(fp)
        X, Y = _xy(fp.position)
        ang = float(fp.position.angle or 0.0)
        c, s = math.cos(math.radians(ang)), math.sin(math.radians(ang))
        gx, gy = X + centre[0] * c + centre[1] * s, Y - centre[0] * s + centre[1] * c
        drills = [float(p.drill.diameter) for p in fp.pads if p.drill is not None and p.drill.diameter]
        pads = [max(float(p.size.X), float(p.size.Y)) for p in fp.pads]
        layout.footprints.append(Footprint(_reference(fp), fp.libId, tuple(board((gx, gy))), ang, (a * MM, b * MM),
                                           "bottom" if fp.layer.startswith("B.") else "top",
                                           max(drills, default=0.0) * MM, max(pads, default=0.0) * MM))
    return layout
