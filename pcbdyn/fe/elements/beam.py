"""Two-node 3-D beam: axial, torsion (G J) and bending in two planes, optional Timoshenko shear,
an orientation vector for the section axes and a rigid offset from the nodes to the beam axis.

Bending uses the interdependent interpolation of Friedman and Kosmatka (1993): cubic transverse
displacement and quadratic rotation tied together by the shear factor
phi = 12 E I / (G A_s L^2). With phi = 0 it is the Hermite cubic Euler-Bernoulli element
(the thesis' cantilever of section 5.4.1 and appendix D.1, ANSYS BEAM4 with consistent mass); with phi > 0 its stiffness is the
shear-flexible matrix of Przemieniecki and its mass the consistent mass of the same shape functions.
A section with ``linear_bending`` takes the linear Timoshenko beam's bending stiffness instead
(w and theta linear, shear at mid-element), the kinematics of the Mindlin shell it is tied to.
Stiffness and mass are integrated with 4-point Gauss quadrature, which is exact for these
polynomials.

Mass: translational rho A, torsional rho (Iy + Iz) (polar moment of the section) always; the
rotary inertia of the section in bending (rho Iz, rho Iy) only if ``prop.rotary_inertia``.
"""

from __future__ import annotations

import numpy as np

from ..model import ModelError
from .line_frame import line_axes

_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_XI = 0.5 * (_GAUSS_X + 1.0)  # points on [0, 1]
_WXI = 0.5 * _GAUSS_W  # weights on [0, 1]


def _check(prop) -> None:
    for name in ("E", "rho", "A"):
        if not getattr(prop, name) > 0:
            raise ModelError(f"BeamProperty.{name} must be > 0, got {getattr(prop, name)}")
    for name in ("Iy", "Iz", "J"):
        if not getattr(prop, name) >= 0:
            raise ModelError(f"BeamProperty.{name} must be >= 0, got {getattr(prop, name)}")
    if not -1.0 < prop.nu < 0.5:
        raise ModelError(f"BeamProperty.nu must lie in (-1, 0.5), got {prop.nu}")
    for name in ("shear_area_y", "shear_area_z"):
        v = getattr(prop, name)
        if v is not None and not v > 0:
            raise ModelError(f"BeamProperty.{name} must be > 0 or None (Euler-Bernoulli), got {v}")
    for name in ("orientation", "offset"):
        if np.shape(getattr(prop, name)) != (3,):
            raise ModelError(f"BeamProperty.{name} must be a 3-vector in global axes")


def local_frame(xyz: np.ndarray, orientation) -> tuple[np.ndarray, np.ndarray]:
    """Lengths (n,) and rotation matrices (n, 3, 3) whose rows are the local axes x, y, z in global
    coordinates: x from node 1 to node 2, y in the plane of x and ``orientation``, z = x cross y."""
    L, ex, ey = line_axes(
        xyz, orientation, "beam",
        "BeamProperty.orientation must be a vector in the plane of the local x-y axes, not along the beam",
    )
    return L, np.stack([ex, ey, np.cross(ex, ey)], axis=1)


def _bending(L: np.ndarray, EI: float, phi: np.ndarray, rhoA: float, rhoI: float):
    """Planar bending K and M (n, 4, 4) for DOFs (w1, theta1, w2, theta2) with theta = dw/dx when
    there is no shear. Friedman-Kosmatka interdependent interpolation; phi may be 0."""
    xi = _XI[None, :]
    Lc = L[:, None]
    p = phi[:, None]
    c = 1.0 / (1.0 + p)
    Nw = c[..., None] * np.stack(
        [
            2 * xi**3 - 3 * xi**2 - p * xi + 1 + p,
            Lc * (xi**3 - (2 + p / 2) * xi**2 + (1 + p / 2) * xi),
            -(2 * xi**3 - 3 * xi**2 - p * xi),
            Lc * (xi**3 - (1 - p / 2) * xi**2 - (p / 2) * xi),
        ],
        axis=-1,
    )
    Nt = c[..., None] * np.stack(
        [6 * (xi**2 - xi) / Lc, 3 * xi**2 - (4 + p) * xi + 1 + p, -6 * (xi**2 - xi) / Lc, 3 * xi**2 - (2 - p) * xi],
        axis=-1,
    )
    dNt = c[..., None] * np.stack(
        [6 * (2 * xi - 1) / Lc**2, (6 * xi - 4 - p) / Lc, -6 * (2 * xi - 1) / Lc**2, (6 * xi - 2 + p) / Lc],
        axis=-1,
    )
    # the shear strain dw/dx - theta is constant, gamma = phi g; with G A_s = 12 EI / (phi L^2) the shear
    # energy G A_s L gamma^T gamma is 12 EI phi / L g g^T, which vanishes for Euler-Bernoulli (phi = 0)
    half = np.full_like(L, 0.5)
    g = np.stack([-1.0 / L, -half, 1.0 / L, -half], axis=-1) / (1.0 + phi)[:, None]
    w = _WXI[None, :] * Lc

    def integral(a):
        return np.einsum("ng,ngi,ngj->nij", w, a, a, optimize=True)

    K = EI * integral(dNt) + (12.0 * EI * phi / L)[:, None, None] * g[:, :, None] * g[:, None, :]
    M = rhoA * integral(Nw)
    if rhoI:
        M += rhoI * integral(Nt)
    return K, M


def _rod(L: np.ndarray, k: float, m: float):
    """Two-node linear rod K and M (n, 2, 2) for stiffness k/L and mass m L (axial or torsion)."""
    one = np.array([[1.0, -1.0], [-1.0, 1.0]])
    cm = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    return (k / L)[:, None, None] * one, (m * L)[:, None, None] * cm


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def _linear_bending(L: np.ndarray, EI: float, GAs: float) -> np.ndarray:
    """Planar bending K (n, 4, 4) for DOFs (w1, theta1, w2, theta2) with w and theta linear: EI on
    d(theta)/dx and G A_s on the shear strain dw/dx - theta at the middle (one point: no locking)."""
    d = np.array([0.0, -1.0, 0.0, 1.0])  # theta2 - theta1
    Kb = (EI / L)[:, None, None] * np.outer(d, d)
    half = np.full_like(L, 0.5)
    g = np.stack([-1.0 / L, -half, 1.0 / L, -half], axis=-1)
    return Kb + (GAs * L)[:, None, None] * g[:, :, None] * g[:, None, :]


def local_matrices(L: np.ndarray, prop):
    """K and M (n, 12, 12) in the local frame, DOFs (u, v, w, rx, ry, rz) at node 1 then node 2.
    With ``prop.linear_bending`` the bending stiffness is the linear Timoshenko beam's
    (:func:`_linear_bending`; shear areas 5/6 A where not given), the mass unchanged."""
    n = L.size
    G = prop.G
    K = np.zeros((n, 12, 12))
    M = np.zeros((n, 12, 12))

    def put(idx, Kp, Mp):
        ix = np.ix_(idx, idx)
        K[:, ix[0], ix[1]] += Kp
        M[:, ix[0], ix[1]] += Mp

    put([0, 6], *_rod(L, prop.E * prop.A, prop.rho * prop.A))
    put([3, 9], *_rod(L, G * prop.J, prop.rho * (prop.Iy + prop.Iz)))
    ri = bool(prop.rotary_inertia)
    s = np.array([1.0, -1.0, 1.0, -1.0])
    # bending in the local x-y plane about z (Iz, shear in y): theta_z = dv/dx;
    # in the local x-z plane about y (Iy, shear in z): theta_y = -dw/dx
    for idx, EI, As, sign in (([1, 5, 7, 11], prop.E * prop.Iz, prop.shear_area_y, np.ones(4)),
                              ([2, 4, 8, 10], prop.E * prop.Iy, prop.shear_area_z, s)):
        phi = 12 * EI / (G * As * L**2) if As else np.zeros(n)
        Kp, Mp = _bending(L, EI, phi, prop.rho * prop.A, prop.rho * EI / prop.E * ri)
        if prop.linear_bending:
            Kp = _linear_bending(L, EI, G * (As or 5.0 / 6.0 * prop.A))
        put(idx, Kp * sign[:, None] * sign[None, :], Mp * sign[:, None] * sign[None, :])
    return K, M


def matrices(xyz: np.ndarray, prop):
    """Beam K and M (n_cells, 12, 12) in global axes at the nodes ``xyz`` (n_cells, 2, 3).

    The beam axis runs through node + ``prop.offset``; nodal DOFs drive it rigidly,
    u_axis = u_node + theta x offset, theta_axis = theta_node, so K = T^T K_axis T and likewise M.
    """
    _check(prop)
    xyz = np.asarray(xyz, dtype=float)
    L, R = local_frame(xyz, prop.orientation)
    Kl, Ml = local_matrices(L, prop)
    n = L.size
    T = np.zeros((n, 12, 12))  # u_local = T u_global
    for k in range(4):
        T[:, 3 * k : 3 * k + 3, 3 * k : 3 * k + 3] = R
    Tt = np.transpose(T, (0, 2, 1))
    K, M = Tt @ Kl @ T, Tt @ Ml @ T
    e = np.asarray(prop.offset, dtype=float)
    if np.any(e != 0):
        t = np.eye(6)
        t[:3, 3:] = -_skew(e)
        To = np.kron(np.eye(2), t)

        def shift(A):  # To^T A To for every cell, as two single large products
            A = (A.reshape(-1, 12) @ To).reshape(n, 12, 12).transpose(0, 2, 1)
            return (A.reshape(-1, 12) @ To).reshape(n, 12, 12).transpose(0, 2, 1)

        K, M = shift(K), shift(M)
    return K, M
