"""The entries of a box description (box.toml) as plain dataclasses in SI units: plates in 3-D, ribs on
them, supports, joints, point masses, configurations; :mod:`.spec` reads them, :mod:`.geometry` places
them in space."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..domain import StructureError

#: plate edges by name: (which coordinate is fixed, its value): u0 is s = 0, v1 is t = 1
EDGES = {"u0": ("s", 0.0), "u1": ("s", 1.0), "v0": ("t", 0.0), "v1": ("t", 1.0)}
SUPPORT_TYPES = ("clamped", "hinged")
RIB_SIDES = ("+n", "-n")
RIB_MODELS = ("beam", "shell")
#: [m] plates meet, points lie on a plate, a rib end lies on its plate, within this
GEOM_TOL = 1e-6
#: most plates a box may have (every pair is checked for a shared edge)
MAX_PLATES = 64


class BoxError(StructureError):
    """A box description that cannot be used; the message names the file, the field and the fix."""


@dataclass(frozen=True)
class BoxMaterial:
    """E [Pa] (a float, or (Eu, Ev) along the plate's u and v for an orthotropic plate), nu, rho [kg/m^3]."""

    E: float | tuple
    nu: float
    rho: float

    @property
    def orthotropic(self) -> bool:
        return isinstance(self.E, tuple)


@dataclass
class Plate:
    """The parallelogram ``origin + s u + t v``, s and t in [0, 1] (origin, u, v [m] in the box frame),
    of ``thickness`` [m] and ``material`` (with the plate's own E and rho where it gives them: smeared
    holes or parts); ``declared``: the material it names, which its ribs have by default; n = u x v
    normalised is its normal."""

    name: str
    origin: np.ndarray
    u: np.ndarray
    v: np.ndarray
    thickness: float
    material: BoxMaterial
    declared: BoxMaterial | None = None

    @property
    def normal(self) -> np.ndarray:
        n = np.cross(self.u, self.v)
        return n / np.linalg.norm(n)

    @property
    def lengths(self) -> tuple:
        """(|u|, |v|) [m]."""
        return float(np.linalg.norm(self.u)), float(np.linalg.norm(self.v))

    def corners(self) -> np.ndarray:
        """(4, 3) corners in the order origin, +u, +u+v, +v (counter-clockwise about n)."""
        o, u, v = self.origin, self.u, self.v
        return np.array([o, o + u, o + u + v, o + v])

    def point(self, a: float, b: float) -> np.ndarray:
        """The point at lengths ``a`` along u and ``b`` along v from the origin [m]."""
        la, lb = self.lengths
        return self.origin + a / la * self.u + b / lb * self.v

    def edge(self, name: str) -> tuple:
        """(start, end) [m] of edge ``name`` (u0, u1, v0, v1)."""
        which, value = EDGES[name]
        if which == "s":
            p = self.origin + value * self.u
            return p, p + self.v
        p = self.origin + value * self.v
        return p, p + self.u

    def coordinates(self, xyz) -> np.ndarray:
        """(s, t, h) of points ``xyz`` (k, 3): xyz = origin + s u + t v + h n."""
        A = np.column_stack([self.u, self.v, self.normal])
        return np.linalg.solve(A, (np.atleast_2d(xyz) - self.origin).T).T

    def distance(self, xyz) -> np.ndarray:
        """Distance [m] of points (k, 3) from the plate (the parallelogram, edges included)."""
        from ..fe.probe import segment_parameter

        p = np.atleast_2d(np.asarray(xyz, float))
        st = self.coordinates(p)
        inside = np.all((st[:, :2] >= 0) & (st[:, :2] <= 1), axis=1)
        c = self.corners()
        edges = []
        for a, b in zip(c, np.roll(c, -1, axis=0)):
            a, b = np.broadcast_to(a, p.shape), np.broadcast_to(b, p.shape)
            edges.append(np.linalg.norm(a + segment_parameter(p, a, b)[:, None] * (b - a) - p, axis=1))
        return np.where(inside, np.abs(st[:, 2]), np.min(edges, axis=0))


@dataclass
class Rib:
    """A straight rib on ``plate`` from ``start`` to ``end`` ((a, b) lengths along u and v from the
    plate's origin [m]), of rectangular section ``height`` x ``width`` [m] standing on the plate's
    ``side`` ("+n" or "-n")."""

    name: str
    plate: str
    start: tuple
    end: tuple
    height: float
    width: float
    side: str
    material: BoxMaterial


@dataclass
class Support:
    """Edge ``edge`` (u0, u1, v0, v1) of ``plate`` held: "clamped" (every DOF) or "hinged" (the
    rotation about the edge free)."""

    plate: str
    edge: str
    type: str


@dataclass
class Joint:
    """The edge shared by ``plates`` (two names) is a rotational spring ``k_rot`` [N m/rad/m] about the
    edge (translations and the other rotations tied); without an entry shared edges are rigid."""

    name: str
    plates: tuple
    k_rot: float


@dataclass
class BoxMass:
    """A point mass [kg] on ``plate`` at ``at`` ((a, b) along u and v [m]), on the node there (no rotary
    inertia: ``inertia`` is 0)."""

    name: str
    plate: str
    at: tuple
    mass: float
    inertia: float = 0.0


@dataclass
class Configuration:
    """A perturbed test configuration: the base box with added ``masses``."""

    name: str
    masses: list = field(default_factory=list)
