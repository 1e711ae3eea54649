"""Section properties, one per element set, so that one updating parameter can change one set.

Every property is a frozen dataclass; :func:`dataclasses.replace` makes a perturbed copy
(which is how parameter sensitivities re-evaluate the few element matrices they touch).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class _HomogeneousMass:
    """The mass of a shell of one density ``rho`` and thickness ``t`` with non-structural mass ``nsm``."""

    def mass_per_area(self) -> float:
        """Translational mass per unit area [kg/m^2]."""
        return self.rho * self.t + self.nsm

    def rotary_inertia_per_area(self) -> float:
        """Rotary inertia per unit area about the mid-surface [kg]."""
        return self.rho * self.t**3 / 12.0


@dataclass(frozen=True)
class ShellProperty(_HomogeneousMass):
    """Homogeneous isotropic shell: Young's modulus E [Pa], Poisson ratio nu, density rho [kg/m^3],
    thickness t [m].

    The element kernels only use the stress resultant matrices below, so an equivalent
    laminate (classical lamination theory) is another class with the same five methods.
    ``nsm`` is a non-structural mass per unit area [kg/m^2] (smeared parts, coatings).
    """

    E: float
    nu: float
    rho: float
    t: float
    nsm: float = 0.0
    shear_factor: float = 5.0 / 6.0

    def membrane(self) -> np.ndarray:
        """In-plane stiffness A (3x3), N = A eps, [N/m]."""
        c = self.E * self.t / (1.0 - self.nu**2)
        return c * np.array([[1.0, self.nu, 0.0], [self.nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - self.nu)]])

    def bending(self) -> np.ndarray:
        """Bending stiffness D (3x3), M = D kappa, [N m]."""
        return self.membrane() * (self.t**2 / 12.0)

    def shear(self) -> np.ndarray:
        """Transverse shear stiffness (2x2), Q = S gamma, [N/m]."""
        G = self.E / (2.0 * (1.0 + self.nu))
        return self.shear_factor * G * self.t * np.eye(2)



@dataclass(frozen=True)
class OrthotropicShellProperty(_HomogeneousMass):
    """Orthotropic shell (a plate whose hole pattern or stiffening differs along two directions, smeared):
    Young's moduli ``Eu`` along the in-plane direction ``axis`` (global axes) and ``Ev`` across it, major
    Poisson ratio ``nu`` (nu_uv; nu_vu = nu Ev / Eu), shear modulus ``G`` (default Huber's
    sqrt(Eu Ev) / (2 (1 + nu))), density ``rho``, thickness ``t``. Its matrices are given with x along
    ``axis``; the shell kernels rotate them into each element's frame
    (:func:`pcbdyn.fe.elements.shell_common.oriented`)."""

    Eu: float
    Ev: float
    nu: float
    rho: float
    t: float
    axis: tuple = (1.0, 0.0, 0.0)
    G: float | None = None
    nsm: float = 0.0
    shear_factor: float = 5.0 / 6.0

    @property
    def shear_modulus(self) -> float:
        return self.G if self.G is not None else float(np.sqrt(self.Eu * self.Ev)) / (2.0 * (1.0 + self.nu))

    def membrane(self) -> np.ndarray:
        nu_vu = self.nu * self.Ev / self.Eu
        d = 1.0 - self.nu * nu_vu
        return self.t * np.array([[self.Eu / d, nu_vu * self.Eu / d, 0.0], [nu_vu * self.Eu / d, self.Ev / d, 0.0],
                                  [0.0, 0.0, self.shear_modulus]])

    def bending(self) -> np.ndarray:
        return self.membrane() * (self.t**2 / 12.0)

    def shear(self) -> np.ndarray:
        return self.shear_factor * self.shear_modulus * self.t * np.eye(2)



@dataclass(frozen=True)
class BeamProperty:
    """3-D beam section. ``orientation`` is a vector in the local x-y plane (not along the axis);
    local y follows it, local z = x cross y. ``Iy``/``Iz`` are second moments about local y/z.
    ``offset`` [m] is the vector from each node to the beam's axis (a rib's centroid above a plate).
    ``shear_area_y``/``shear_area_z`` switch on Timoshenko shear (None: Euler-Bernoulli).
    ``rotary_inertia`` switches the section's rotary inertia in bending; the twisting inertia
    rho (Iy + Iz) is always kept so that no DOF is left without mass. ``linear_bending``: the
    bending stiffness of the linear Timoshenko beam (for a beam tied to a Mindlin shell, whose w
    and theta are interpolated independently; see :mod:`.elements.beam`).
    """

    E: float
    nu: float
    rho: float
    A: float
    Iy: float
    Iz: float
    J: float
    orientation: tuple = (0.0, 0.0, 1.0)
    offset: tuple = (0.0, 0.0, 0.0)
    shear_area_y: float | None = None
    shear_area_z: float | None = None
    rotary_inertia: bool = True
    linear_bending: bool = False

    @property
    def G(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))


@dataclass(frozen=True)
class SpringProperty:
    """Discrete 6-DOF spring in global axes: ``k`` = (kx, ky, kz [N/m], krx, kry, krz [N m/rad]) on the
    diagonal, or a symmetric 6x6 matrix.

    A set of 1-node cells connects each node to ground; 2-node cells connect node pairs. With
    ``weights`` (one per node of a cell, e.g. a shell cell's shape functions at a point), each
    cell is one spring to ground at the point whose motion the weights interpolate from the
    cell's nodes: K = (w w^T) (x) k, a support between nodes that stays where it is on any mesh.
    """

    k: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    weights: tuple | None = None


@dataclass(frozen=True)
class EdgeSpringProperty:
    """Springs distributed along a line of element edges (2-node cells), per unit length.

    ``k`` = (k1, k2, k3 [N/m/m], kr1, kr2, kr3 [N m/rad/m]) in the edge frame: axis 1 along the
    edge, axis 3 along ``normal`` (the shell normal), axis 2 = 3 x 1. A wedge-lock guide is a
    rotational stiffness kr1 about the edge with the translations held.
    """

    k: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    normal: tuple = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class MassProperty:
    """Point mass ``m`` [kg] with rotary inertia ``inertia`` (3,) diagonal or (3,3) [kg m^2], global axes.
    ``footprint`` (n_samples, nodes per cell): for a cell of several nodes, the interpolation
    weights of points sampling the body's footprint (None: the nodes themselves sample it)."""

    m: float
    inertia: tuple = (0.0, 0.0, 0.0)
    footprint: object = field(default=None, compare=False)

    def inertia_matrix(self) -> np.ndarray:
        J = np.asarray(self.inertia, dtype=float)
        return np.diag(J) if J.ndim == 1 else J


@dataclass(frozen=True)
class EmbeddedBeamProperty:
    """A ``beam`` section between two points inside host shell cells (element type
    ``embedded_beam2``): ``weights`` (n_cells, 2, nodes_per_cell) interpolate each end's six DOFs
    from the cell's nodes, so the beam moves with the shell it is tied to and can run straight
    across a mesh whose node rows do not (a rib bonded along a line the mesh does not follow).
    Per-cell data: :meth:`cells` gives the property of a slice of the set's cells."""

    beam: BeamProperty
    weights: object = field(compare=False)

    def cells(self, a: int, b: int) -> "EmbeddedBeamProperty":
        return EmbeddedBeamProperty(self.beam, np.asarray(self.weights)[a:b])
