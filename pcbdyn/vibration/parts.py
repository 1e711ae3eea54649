"""The parts of a board that Steinberg's check judges, with what his formula needs of each: the
package constant (from the part's library entry), the part's length L and direction, and the
board span B along that direction.

L is the footprint's longer side; B is the chord of the board outline through the part's centre
along that side (for a rectangular board, the edge length parallel to the part, as Steinberg
defines it). Holes in the board do not shorten B: the board edge is what Steinberg measures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..components.library import LibraryError, find_package
from ..fe.curvature import curvature_matrix
from ..fe.model import SHELL_TYPES
from ..fe.probe import model_probe
from .spectra import VibrationError

#: Steinberg's package constants by kind of part, for the message that asks for one
CONSTANTS_HINT = ("Steinberg's constants: 0.75 axial-leaded and fine-pitch surface-mount parts, 1.0 standard DIP and "
                  "through-hole PGA, 1.26 side-brazed DIP, J-lead chip carrier and parts with parallel rows of wires, "
                  "1.75 BGA, 2.25 leadless ceramic chip carrier")
#: points across the footprint (fractions of the half-sizes) over which curvatures are averaged
_SAMPLES = np.array([-2.0 / 3.0, 0.0, 2.0 / 3.0])


@dataclass
class Part:
    """One judged part: reference, package, Steinberg constant ``c``, centre ``at`` (x, y) [m],
    ``length`` L [m], ``angle`` of its long side [rad], board ``span`` B [m] along it, and
    ``samples`` (9, 2): points over the footprint where its curvature is read."""

    ref: str
    package: str
    c: float
    at: np.ndarray
    length: float
    angle: float
    span: float
    samples: np.ndarray


@dataclass
class PartVerdict:
    """What the part results of ``vibe`` and ``shock`` share: the part (reference, package, Steinberg
    constant, board span B and length L [m], position factor r read from the model), the margin from
    their ``ratio`` of response to allowable, and the JSON row (with the margin and ``ok``)."""

    ref: str
    package: str
    c: float
    span_m: float
    length_m: float
    position_factor: float

    @property
    def margin(self) -> float:
        """allowable / response - 1: negative when the part fails (infinite when nothing moves)."""
        return 1.0 / self.ratio - 1.0 if self.ratio > 0 else float("inf")

    def to_dict(self) -> dict:
        d = dict(self.__dict__)
        d["margin"] = None if np.isinf(self.margin) else self.margin
        d["ok"] = self.ok
        return d


def _chord(outline, centre, angle) -> float:
    """Length of the outline's chord through ``centre`` along ``angle`` (holes ignored)."""
    from shapely.geometry import LineString, Point, Polygon

    poly = Polygon(outline.vertices)
    lo, hi = outline.bbox
    reach = 2.0 * float(np.hypot(*(hi - lo)))
    d = np.array([math.cos(angle), math.sin(angle)])
    cut = poly.intersection(LineString([centre - reach * d, centre + reach * d]))
    pieces = list(getattr(cut, "geoms", [cut]))
    return float(min(pieces, key=lambda g: g.distance(Point(centre))).length)


def _part(board, comp, pkg) -> Part:
    a, b = comp.size
    angle = comp.rotation + (0.0 if a >= b else 0.5 * math.pi)
    c, s = math.cos(comp.rotation), math.sin(comp.rotation)
    u, v = np.meshgrid(_SAMPLES * a / 2, _SAMPLES * b / 2)
    local = np.column_stack([u.ravel(), v.ravel()])
    samples = np.asarray(comp.at) + local @ np.array([[c, s], [-s, c]])
    at = np.asarray(comp.at, dtype=float)
    return Part(comp.ref, pkg.name, pkg.steinberg_c, at, max(a, b), angle, _chord(board.outline, at, angle), samples)


def judged_parts(board, exclude=()) -> list:
    """The :class:`Part` of every component not in ``exclude``; a clear error naming every part
    whose library entry gives no Steinberg constant (or that has no library package)."""
    exclude = set(exclude)
    unknown = exclude - {c.ref for c in board.components}
    if unknown:
        raise VibrationError(f"--exclude {', '.join(sorted(unknown))}: no such part in {board.path.name} "
                             f"(parts: {', '.join(c.ref for c in board.components) or 'none'})")
    parts, missing = [], []
    for comp in board.components:
        if comp.ref in exclude:
            continue
        try:
            pkg = find_package(comp.package, board.path.parent) if comp.package else None
        except LibraryError as exc:
            raise VibrationError(str(exc)) from None
        if pkg is None or pkg.steinberg_c is None:
            where = f"package {comp.package}, {pkg.path}" if pkg is not None else "no library package"
            missing.append((comp.ref, where))
            continue
        parts.append(_part(board, comp, pkg))
    if missing:
        listed = "; ".join(f"{ref} ({where})" for ref, where in missing)
        raise VibrationError(
            f"{board.path.name}: no Steinberg package constant for {listed}. Add 'steinberg_c = <value>' with its "
            f"source to the [package] table of the part's library file ({CONSTANTS_HINT}), give the part a library "
            f"package that has one, or leave it out with --exclude {missing[0][0]}")
    return parts


def shell_nodes(model) -> np.ndarray:
    """The nodes of the model's shells (the board), where board maps are drawn."""
    return np.unique(np.concatenate([es.conn.ravel() for es in model.sets.values() if es.etype in SHELL_TYPES]))


def _curvature_rows(model, parts) -> tuple:
    """(along L, across L) curvature operators, each (n_parts, n_dof) sparse, averaged over the
    sample points of each footprint; across L is along L turned by 90 degrees."""
    samples = np.vstack([p.samples for p in parts])
    C = curvature_matrix(model, samples)
    per = samples.shape[0] // len(parts)
    mean = sp.kron(sp.eye(len(parts)), np.full((1, per), 1.0 / per), format="csr")
    kxx, kyy, kxy = (mean @ C[k::3] for k in range(3))
    out = []
    for angle in (np.array([p.angle for p in parts]), np.array([p.angle for p in parts]) + 0.5 * np.pi):
        c, s = np.cos(angle), np.sin(angle)
        out.append(sp.diags(c * c) @ kxx + sp.diags(s * s) @ kyy + sp.diags(c * s) @ kxy)
    return tuple(out)


def part_readers(model, parts, axis: str, direction=None) -> dict:
    """What is read at the parts, as operators on the model's DOFs (n_parts, n_dof): "z", the
    displacement normal to the board at each centre; "acceleration", the motion along the shaken
    ``axis`` there (or along ``direction``, a unit vector in the board frame: a card in a housing shaken
    along the housing's axis); "curvature_along" and "curvature_across", the curvatures along and
    across each part's long side averaged over its footprint."""
    centres = np.column_stack([np.array([p.at for p in parts]), np.zeros(len(parts))])
    along, across = _curvature_rows(model, parts)
    direction = np.eye(3)["xyz".index(axis)] if direction is None else direction
    return {"z": model_probe(model, centres).P,
            "acceleration": model_probe(model, centres, direction).P,
            "curvature_along": along, "curvature_across": across}
