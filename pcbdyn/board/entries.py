"""The entries of a board description as plain dataclasses in SI units (outline, parts, fixtures,
masses, effect entries, configurations, analysis settings); :mod:`.spec` reads them from board.toml."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from matplotlib.path import Path as PolyPath

from ..domain import Analysis, StructureError  # noqa: F401  (Analysis: a board entry too)

FIXTURE_TYPES = ("free", "clamped_edge", "hinged_edge", "wedge_lock", "standoff", "point_spring", "edge_spring")
MIN_SEGMENT = 1e-4  # [m] shortest segment of an edge spring, line mass or stiffener piece
GEOM_TOL = 1e-7  # [m] touching footprints or points on an edge are accepted within this
MIN_SPAN = 1e-3  # [m] the narrowest a board's outline may be


class BoardError(StructureError):
    """A board description that cannot be used; the message names the file, the field and the fix."""


@dataclass
class Outline:
    """Board outline in the board frame (origin at the lower-left corner of the bounding box)."""

    vertices: np.ndarray  # (n, 2) counter-clockwise
    holes: list = field(default_factory=list)  # list of (m, 2) arrays
    is_rectangle: bool = False

    @property
    def bbox(self):
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    def area(self) -> float:
        def shoelace(v):
            x, y = v[:, 0], v[:, 1]
            return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

        return shoelace(self.vertices) - sum(shoelace(h) for h in self.holes)

    def contains(self, pts, tol=GEOM_TOL) -> np.ndarray:
        """True for points on the board (boundary included, holes excluded)."""
        pts = np.atleast_2d(pts)
        inside = PolyPath(self.vertices).contains_points(pts, radius=tol) | PolyPath(
            self.vertices).contains_points(pts, radius=-tol)
        for h in self.holes:
            inside &= ~PolyPath(h).contains_points(pts, radius=-tol) & ~PolyPath(h).contains_points(pts, radius=tol)
        return inside

    def edge_extent(self, axis: int, value: float, tol=GEOM_TOL):
        """(lo, hi) of the outline's boundary lying on the line x=value (axis 0) or y=value (axis 1),
        or None when no outline segment lies on it."""
        v = self.vertices
        w = np.roll(v, -1, axis=0)
        on = (np.abs(v[:, axis] - value) < tol) & (np.abs(w[:, axis] - value) < tol)
        if not on.any():
            return None
        other = 1 - axis
        seg = np.concatenate([v[on, other], w[on, other]])
        return float(seg.min()), float(seg.max())


@dataclass
class Component:
    ref: str
    at: tuple  # centre (x, y) [m]
    rotation: float  # [rad]
    size: tuple  # footprint (a, b) [m] before rotation
    height: float  # body height [m] (rotary inertia of a lumped part)
    mass: float  # [kg]
    model: str
    thickness: float | None  # equivalent thickness [m] (equivalent_thickness model)
    E: float | None = None  # region Young's modulus (smeared_local); default: the board's
    rho: float | None = None  # region density as given (then it set ``mass``); default: from mass
    package: str | None = None

    def corners(self) -> np.ndarray:
        a, b = self.size
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        local = np.array([[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, b / 2], [-a / 2, b / 2]])
        return np.asarray(self.at) + local @ np.array([[c, s], [-s, c]])

    @property
    def area(self) -> float:
        return self.size[0] * self.size[1]


@dataclass
class Fixture:
    name: str
    type: str
    edge: tuple | None = None  # (axis, value): axis 0 -> "x=value", 1 -> "y=value"
    width: float = 0.0  # contact strip [m]
    k_rot: float | str | None = None  # N m/rad/m, or "clamped" / "hinged"
    at: tuple | None = None
    k: float | str | None = None  # N/m or "rigid"
    diameter: float = 0.0  # standoff pad held rigid [m]
    segment: tuple | None = None  # edge_spring: ((x0, y0), (x1, y1)) [m]


@dataclass
class PointMass:
    name: str
    at: tuple
    mass: float
    inertia: float = 0.0  # rotary inertia about the in-plane axes [kg m^2]


@dataclass
class LineMass:
    """A mass [kg] spread uniformly along a straight segment ((x0, y0), (x1, y1)) [m]."""

    name: str
    segment: tuple
    mass: float


@dataclass
class RibSection:
    """A stiffener's fixed material and height; its width follows from EI (defaults: aluminium,
    4 mm, as the diagnosis ``stiffener`` kind)."""

    E: float = 70e9
    nu: float = 0.33
    rho: float = 2700.0
    h: float = 4e-3


@dataclass
class Stiffener:
    """A rib of bending stiffness EI [N m^2] along ``path`` ((x, y), ...) [m] of straight pieces."""

    name: str
    path: tuple
    EI: float
    section: RibSection = field(default_factory=RibSection)


@dataclass
class Region:
    """Shells inside ``polygon`` (m, 2) [m] get ``stiffness_factor`` times their stiffness, and ``mass``
    [kg] (None: none declared) spread uniformly over their area (a heat sink, a shield can, potting)."""

    name: str
    polygon: np.ndarray
    stiffness_factor: float = 1.0
    mass: float | None = None


@dataclass
class Configuration:
    name: str
    masses: list


