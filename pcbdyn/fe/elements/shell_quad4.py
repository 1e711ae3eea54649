"""Four-node flat shell: bilinear membrane with a drilling rotation, MITC4 Mindlin bending.

- Membrane: bilinear isoparametric u, v, 2x2 Gauss.
- Drilling: Hughes-Brezzi penalty gamma (theta_z - (v_x - u_y) / 2)^2 with bilinear theta_z,
  integrated with 2x2 Gauss. One-point integration would leave a checkerboard pattern of
  theta_z with zero energy (a spurious mechanism of the mesh); with 2x2 points there is none,
  and since on a parallelogram the in-plane rotation of a bilinear field is linear, theta_z can
  follow it exactly, so the penalty does not lock the membrane. A rigid rotation has zero
  penalty energy, so the six rigid-body modes stay exact.
- Bending: Reissner-Mindlin with the MITC4 assumed transverse shear of Bathe and Dvorkin (1985):
  the covariant shear strains are sampled at the edge midpoints and interpolated across, which
  removes shear locking for thin plates.
- Mass: consistent. u, v and the rotary inertia use the bilinear functions
  (:func:`.shell_common.rotary_mass`); w uses the incomplete bicubic Hermite functions of
  the nodal w and the slopes given by the bending rotations (thin-plate kinematics), as a
  beam's consistent mass does. With bilinear w the kinetic energy of a bending wave is
  underestimated by about (k h)^2 / 6 (wavenumber k, element size h): the worst of the first
  eight NAFEMS simply supported frequencies at 32 x 32 is then 0.9 % high, against 0.28 %
  with the Hermite w.

The element is formed in the frame of its mean plane; a warped quad is formed on its nodes
projected onto that plane and tied to them by rigid links (:func:`.shell_common.rigid_offsets`),
then rotated to global axes.
"""

from __future__ import annotations

import numpy as np

from ..model import ModelError
from .shell_common import btdb, local_frame, merge, oriented, rigid_offsets, rotary_mass, section, to_global

_XI = np.array([-1.0, 1.0, 1.0, -1.0])
_ETA = np.array([-1.0, -1.0, 1.0, 1.0])
_G = 1.0 / np.sqrt(3.0)
_GAUSS = [(-_G, -_G), (_G, -_G), (_G, _G), (-_G, _G)]  # weights 1


def _shape(xi: float, eta: float):
    """Bilinear N (4,) and dN/d(xi, eta) (2, 4)."""
    N = 0.25 * (1 + _XI * xi) * (1 + _ETA * eta)
    dN = np.array([0.25 * _XI * (1 + _ETA * eta), 0.25 * _ETA * (1 + _XI * xi)])
    return N, dN


def _covariant_shear_row(xl, xi, eta, direction):
    """Row (n, 12) of the bending block giving the covariant shear strain gamma_xi (direction 0)
    or gamma_eta (1) at (xi, eta): dw/dxi_d + (dx/dxi_d) . beta, with beta = (theta_y, -theta_x)."""
    N, dN = _shape(xi, eta)
    dx = np.einsum("a,nai->ni", dN[direction], xl)  # (n, 2): dx/dxi_d, dy/dxi_d
    row = np.zeros((xl.shape[0], 4, 3))
    row[:, :, 0] = dN[direction]
    row[:, :, 2] = N[None, :] * dx[:, 0:1]
    row[:, :, 1] = -N[None, :] * dx[:, 1:2]
    return row.reshape(-1, 12)


_G4, _W4 = np.polynomial.legendre.leggauss(4)


def _hermite(s, si):
    """1-D cubic Hermite value and slope functions of the node at si = +-1, at points s."""
    a = 1.0 + si * s
    return a * a * (2.0 - si * s) / 4.0, si * a * a * (si * s - 1.0) / 4.0


def _hermite_w_mass(xl, m):
    """Bending-block mass (n, 12, 12) of the deflection w interpolated by incomplete bicubic
    Hermite functions of the nodal w and slopes, the slopes taken from the rotations
    (Kirchhoff: grad w = (-theta_y, theta_x)). 4 x 4 Gauss points: exact on parallelograms."""
    n = xl.shape[0]
    xi, eta = (a.ravel() for a in np.meshgrid(_G4, _G4))
    wts = np.outer(_W4, _W4).ravel()
    Nw = np.zeros((xi.size, 4, 3))
    for a in range(4):
        h0x, h1x = _hermite(xi, _XI[a])
        h0y, h1y = _hermite(eta, _ETA[a])
        Nw[:, a] = np.stack([h0x * h0y, h1x * h0y, h0x * h1y], axis=1)
    Nw = Nw.reshape(-1, 12)
    dN = np.stack([_shape(x, e)[1] for x, e in zip(xi, eta)])  # (p, 2, 4)
    J = np.einsum("pka,nai->npki", dN, xl)
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    Mh = ((m * det * wts) @ np.einsum("pa,pb->pab", Nw, Nw).reshape(-1, 144)).reshape(n, 12, 12)
    Jn = np.einsum("cka,nai->ncki", np.stack([_shape(_XI[c], _ETA[c])[1] for c in range(4)]), xl)
    # (w, w,xi, w,eta) of each node from its (w, theta_x, theta_y): w,xi_k = J_k0 w,x + J_k1 w,y
    # with w,x = -theta_y, w,y = theta_x
    T = np.zeros((n, 4, 3, 4, 3))
    for c in range(4):
        T[:, c, 0, c, 0] = 1.0
        T[:, c, 1:, c, 1] = Jn[:, c, :, 1]
        T[:, c, 1:, c, 2] = -Jn[:, c, :, 0]
    T = T.reshape(n, 12, 12)
    return np.matmul(T.transpose(0, 2, 1), np.matmul(Mh, T))


def local_matrices(xl: np.ndarray, prop, sec=None):
    """Stiffness and mass (n, 24, 24) in the element frame from in-plane coordinates (n, 4, 2) (``sec``:
    the section in the element frames, default :func:`.shell_common.section` of ``prop``)."""
    sec = section(prop) if sec is None else sec
    n = xl.shape[0]
    # MITC4 tying points: gamma_xi at (0, -1), (0, 1); gamma_eta at (-1, 0), (1, 0)
    gxi_b, gxi_t = (_covariant_shear_row(xl, 0.0, s, 0) for s in (-1.0, 1.0))
    geta_l, geta_r = (_covariant_shear_row(xl, s, 0.0, 1) for s in (-1.0, 1.0))

    # strain rows per Gauss point. Membrane block (u, v, theta_z per node): membrane strains,
    # drilling; bending block (w, theta_x, theta_y): curvatures, transverse shear strains
    Bm = np.zeros((n, 4, 4, 4, 3))
    Bb = np.zeros((n, 4, 5, 4, 3))
    wdet = np.zeros((n, 4))
    Ns = np.zeros((4, 4))
    for g, (xi, eta) in enumerate(_GAUSS):
        N, dN = _shape(xi, eta)
        J = np.einsum("ka,nai->nki", dN, xl)  # J[k, i] = d x_i / d xi_k
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        if np.any(det <= 0):
            bad = np.flatnonzero(det <= 0)[:5].tolist()
            raise ModelError(f"quad4 cells {bad} are not convex or have crossed nodes (Jacobian <= 0)")
        invJ = np.stack([np.stack([J[:, 1, 1], -J[:, 0, 1]], -1), np.stack([-J[:, 1, 0], J[:, 0, 0]], -1)], 1)
        invJ /= det[:, None, None]
        dx, dy = np.einsum("nik,ka->ina", invJ, dN)  # dN/dx, dN/dy (n, 4)
        m, b = Bm[:, g], Bb[:, g]
        m[:, 0, :, 0] = dx  # u,x
        m[:, 1, :, 1] = dy  # v,y
        m[:, 2, :, 0] = dy  # u,y + v,x
        m[:, 2, :, 1] = dx
        m[:, 3, :, 2] = N  # theta_z - (v,x - u,y) / 2
        m[:, 3, :, 1] = -0.5 * dx
        m[:, 3, :, 0] = 0.5 * dy
        b[:, 0, :, 2] = dx  # kappa = (beta_x,x, beta_y,y, beta_x,y + beta_y,x)
        b[:, 1, :, 1] = -dy
        b[:, 2, :, 2] = dy
        b[:, 2, :, 1] = -dx
        gcov = np.stack([0.5 * (1 - eta) * gxi_b + 0.5 * (1 + eta) * gxi_t,
                         0.5 * (1 - xi) * geta_l + 0.5 * (1 + xi) * geta_r], axis=1)
        b[:, 3:5] = np.einsum("nik,nkd->nid", invJ, gcov).reshape(n, 2, 4, 3)  # (gamma_xz, gamma_yz)
        wdet[:, g] = det
        Ns[g] = N
    lead = np.shape(sec.A)[:-2]  # (n, 1) for sections rotated per cell
    Cm = np.zeros(lead + (4, 4))
    Cm[..., :3, :3], Cm[..., 3, 3] = sec.A, sec.drilling
    Cb = np.zeros(lead + (5, 5))
    Cb[..., :3, :3], Cb[..., 3:, 3:] = sec.D, sec.S
    K = merge(btdb(Bm.reshape(n, 4, 4, 12), Cm, wdet), btdb(Bb.reshape(n, 4, 5, 12), Cb, wdet))
    Mm, Mb = rotary_mass(Ns, wdet, sec)
    return K, merge(Mm, Mb + _hermite_w_mass(xl, sec.m))


def matrices(xyz: np.ndarray, prop):
    """Global stiffness and mass (n_cells, 24, 24) of quad4 cells with nodes ``xyz`` (n_cells, 4, 3)."""
    xyz = np.asarray(xyz, dtype=float)
    R, xl, h = local_frame(xyz)
    Kl, Ml = local_matrices(xl, prop, oriented(prop, R))
    return to_global(rigid_offsets(Kl, h), R), to_global(rigid_offsets(Ml, h), R)
