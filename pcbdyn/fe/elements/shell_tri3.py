"""Three-node flat shell: Allman membrane with drilling rotations, DKMT (Mindlin) bending.

- Membrane: Allman's (1984) triangle. u, v are quadratic; the midside values come from the
  corner displacements plus the normal displacement L (theta_z,j - theta_z,i) / 8 implied by the
  corner drilling rotations. Its one spurious mode (all theta_z equal, no displacement) is
  removed by the Hughes-Brezzi penalty gamma (theta_z - (v_x - u_y) / 2)^2 at the centroid.
- Bending: the discrete Kirchhoff-Mindlin triangle (DKMT, Katili 1993), the Reissner-Mindlin
  extension of the discrete Kirchhoff triangle (DKT, Batoz, Bathe and Ho 1980) on the same nine
  DOFs. The rotations beta are quadratic, with a tangential midside increment d_k on each edge k.
  Along the edge the transverse shear is constant, gamma_k = (w_j - w_i) / L + the mean tangential
  rotation + 2 d_k / 3, and moment equilibrium ties it to d_k: gamma_k = -2 phi_k d_k / 3 with
  phi_k = 12 D_ss / (S_ss L^2) (D_ss, S_ss: the section's bending and shear stiffness along the
  edge). The three edge shears give the element's shear field by the lowest-order rotated
  Raviart-Thomas interpolation (the tying of MITC3). For phi -> 0 (thin plates, or the Kirchhoff
  limit ``with_shear_factor`` makes) d_k is DKT's and the shear energy vanishes, so the element
  is free of shear locking; for thick plates it follows Mindlin theory as MITC4 does, and a mesh
  mixing triangles and quads keeps one plate theory.
- Mass: u, v and the rotary inertia with the linear shape functions; w with the cubic of
  Bazeley, Cheung, Irons and Zienkiewicz (BCIZ, 1965) in the same nine bending DOFs, whose
  edge slopes are the DKT ones. A linear w would overestimate bending frequencies by about
  (k h)^2 / 12 (wavenumber k, element size h).

Stiffness uses the 3-point rule (exact for these quadratic integrands); the BCIZ mass is
integrated exactly with the area-coordinate monomial formula.
"""

from __future__ import annotations

from itertools import permutations
from math import factorial

import numpy as np

from .shell_common import btdb, local_frame, merge, oriented, rotary_mass, section, to_global

_GP = np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]])  # (xi, eta), weights 1/6 each
_EDGES = ((0, 1), (1, 2), (2, 0))  # midside points 3, 4, 5 of the 6-node interpolation


def _quadratic(xi: float, eta: float) -> np.ndarray:
    """Derivatives (2, 6) of the 6-node quadratic shape functions w.r.t. (xi, eta)."""
    L = np.array([1 - xi - eta, xi, eta])
    dL = np.array([[-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]])  # dL_i / d(xi, eta)
    d = np.zeros((2, 6))
    for i in range(3):
        d[:, i] = (4 * L[i] - 1) * dL[:, i]
    for k, (i, j) in enumerate(_EDGES):
        d[:, 3 + k] = 4 * (dL[:, i] * L[j] + L[i] * dL[:, j])
    return d


def _unit(n: int, pairs) -> np.ndarray:
    """(n, 2, 9) zero array with the given (row, column, value) entries; block DOF 3 a + d."""
    E = np.zeros((n, 2, 9))
    for row, col, val in pairs:
        E[:, row, col] = val
    return E


def _edges(xl: np.ndarray):
    """Per edge: length (n,), unit tangent s (n, 2) from i to j, outward normal (n, 2)."""
    out = []
    for i, j in _EDGES:
        d = xl[:, j] - xl[:, i]
        L = np.linalg.norm(d, axis=1)
        s = d / L[:, None]
        out.append((L, s, np.stack([s[:, 1], -s[:, 0]], axis=1)))
    return out


def _corners(n: int):
    """Maps (n, 2, 9) of the corners' (u, v) from the membrane block and beta = (theta_y, -theta_x)
    from the bending block (w, theta_x, theta_y per node)."""
    U = [_unit(n, [(0, 3 * a, 1.0), (1, 3 * a + 1, 1.0)]) for a in range(3)]
    B = [_unit(n, [(0, 3 * a + 2, 1.0), (1, 3 * a + 1, -1.0)]) for a in range(3)]
    return U, B


def _residuals(n: int, edges, B):
    """Per edge, the row (n, 9) of (w_j - w_i) / L + s . (beta_i + beta_j) / 2: the edge's mean
    transverse shear when beta is linear along it (the Kirchhoff condition sets it to zero)."""
    out = []
    for (i, j), (L, s, _) in zip(_EDGES, edges):
        dw = _unit(n, [(0, 3 * j, 1.0), (0, 3 * i, -1.0)])[:, 0] / L[:, None]
        out.append(dw + 0.5 * np.einsum("ni,nid->nd", s, B[i] + B[j]))
    return out


def _fields(xl: np.ndarray, edges, phi: np.ndarray):
    """Maps (n, 6, 2, 9) to (u, v) from the membrane block and to beta from the bending block, at
    the six points of the quadratic interpolation (corners, then midsides of edges 1-2, 2-3, 3-1);
    and the edges' constant tangential shears (n, 3, 9). ``edges``: :func:`_edges`; ``phi`` (n, 3):
    the edges' shear parameters; the tangential midside increment is d_k = -3 r_k / (2 (1 + phi_k))
    for the residual r_k of :func:`_residuals`, and the edge shear r_k + 2 d_k / 3 =
    phi_k r_k / (1 + phi_k)."""
    n = xl.shape[0]
    U, B = _corners(n)
    res = _residuals(n, edges, B)
    gam = []
    for k, ((i, j), (L, s, nrm)) in enumerate(zip(_EDGES, edges)):
        tz = _unit(n, [(0, 3 * j + 2, 1.0), (0, 3 * i + 2, -1.0)])[:, 0]  # theta_z,j - theta_z,i
        U.append(0.5 * (U[i] + U[j]) + (L / 8.0)[:, None, None] * nrm[:, :, None] * tz[:, None, :])
        d = (-1.5 / (1.0 + phi[:, k]))[:, None] * res[k]
        B.append(0.5 * (B[i] + B[j]) + s[:, :, None] * d[:, None, :])
        gam.append((phi[:, k] / (1.0 + phi[:, k]))[:, None] * res[k])
    return np.stack(U, axis=1), np.stack(B, axis=1), np.stack(gam, axis=1)


def _along(M: np.ndarray, t: np.ndarray) -> np.ndarray:
    """t^T M t per cell for matrices M (3, 3), (2, 2) or per cell (n, 1, ., .) and vectors t (n, .)."""
    M = np.asarray(M)
    M = np.broadcast_to(M.reshape((-1,) + M.shape[-2:]), (t.shape[0],) + M.shape[-2:])
    return np.einsum("ni,nij,nj->n", t, M, t)


def _shear_parameters(edges, sec) -> np.ndarray:
    """phi_k = 12 D_ss / (S_ss L_k^2) per edge (n, 3): D_ss the bending stiffness for curvature
    along the edge, S_ss the shear stiffness along it (``edges``: :func:`_edges`)."""
    out = []
    for L, s, _ in edges:
        c, e = s[:, 0], s[:, 1]
        curvature = np.stack([c * c, e * e, 2 * c * e], axis=1)  # (kxx, kyy, 2 kxy) of a unit k_ss
        out.append(12.0 * _along(sec.D, curvature) / (_along(sec.S, s) * L * L))
    return np.stack(out, axis=1)


def _shear_rows(xl: np.ndarray, edges, gam: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Rows (n, g, 2, 9) of (gamma_xz, gamma_yz) at ``points`` (n, g, 2) of the field
    a + c (-(y - y0), x - x0) (x0: centroid) whose tangential component on edge k is gam[:, k]."""
    x0 = xl.mean(axis=1)
    A = np.zeros((xl.shape[0], 3, 3))
    for k, ((i, _), (_, s, _)) in enumerate(zip(_EDGES, edges)):
        p = xl[:, i] - x0
        A[:, k] = np.stack([s[:, 0], s[:, 1], p[:, 0] * s[:, 1] - p[:, 1] * s[:, 0]], axis=1)
    coef = np.linalg.solve(A, gam)  # (n, 3, 9): a_x, a_y, c
    r = points - x0[:, None]
    return np.stack([coef[:, None, 0] - r[..., 1, None] * coef[:, None, 2],
                     coef[:, None, 1] + r[..., 0, None] * coef[:, None, 2]], axis=2)


def _gradients(dNx: np.ndarray, F: np.ndarray):
    """d/dx and d/dy (n, 2, 9) of a field F (n, 6, 2, 9), from shape derivatives dNx (n, 2, 6)."""
    return np.einsum("nI,nIcd->ncd", dNx[:, 0], F), np.einsum("nI,nIcd->ncd", dNx[:, 1], F)


def _strain_rows(dNx: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(n, 3, 9) rows of (f_x,x, f_y,y, f_x,y + f_y,x) for a field F (n, 6, 2, 9)."""
    gx, gy = _gradients(dNx, F)
    return np.stack([gx[:, 0], gy[:, 1], gy[:, 0] + gx[:, 1]], axis=1)


#: cubic basis in area coordinates: L_i, L_i^2 L_j (i != j), L1 L2 L3, as exponent triples
_CUBIC = [tuple(int(k == i) for k in range(3)) for i in range(3)]
_CUBIC += [tuple(2 * (k == i) + (k == j) for k in range(3)) for i, j in permutations(range(3), 2)]
_CUBIC += [(1, 1, 1)]
#: integral of basis_p * basis_q over a triangle, divided by its area
_GRAM = np.array(
    [
        [
            2.0 * np.prod([factorial(a + b) for a, b in zip(p, q)]) / factorial(sum(p) + sum(q) + 2)
            for q in _CUBIC
        ]
        for p in _CUBIC
    ]
)


def _bciz_w_mass(xl: np.ndarray, area: np.ndarray, m: float) -> np.ndarray:
    """Bending-block mass (n, 9, 9) of w = sum a_i L_i + sum_{i!=j} c_ij (L_i^2 L_j + L1 L2 L3 / 2),
    with a_i = w_i and c_ij = (x_j - x_i) . grad w_i - (w_j - w_i), grad w_i = (-theta_y, theta_x)_i.
    The L1 L2 L3 coefficient makes the cubic reproduce every quadratic w."""
    n = xl.shape[0]
    C = np.zeros((n, 10, 9))
    for i in range(3):
        C[:, i, 3 * i] = 1.0
    for p, (i, j) in enumerate(permutations(range(3), 2)):
        d = xl[:, j] - xl[:, i]
        row = C[:, 3 + p]
        row[:, 3 * i + 2] = -d[:, 0]
        row[:, 3 * i + 1] = d[:, 1]
        row[:, 3 * j] -= 1.0
        row[:, 3 * i] += 1.0
        C[:, 9] += 0.5 * row
    return (m * area)[:, None, None] * np.matmul(C.transpose(0, 2, 1), np.matmul(_GRAM, C))


def local_matrices(xl: np.ndarray, prop, sec=None):
    """Stiffness and mass (n, 18, 18) in the element frame from in-plane coordinates (n, 3, 2) (``sec``:
    the section in the element frames, default :func:`.shell_common.section` of ``prop``)."""
    sec = section(prop) if sec is None else sec
    n = xl.shape[0]
    J = np.stack([xl[:, 1] - xl[:, 0], xl[:, 2] - xl[:, 0]], axis=1)  # J[k, i] = d x_i / d xi_k
    area = 0.5 * (J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0])
    invJ = np.linalg.inv(J)
    edges = _edges(xl)
    U, Bt, gam = _fields(xl, edges, _shear_parameters(edges, sec))

    Bm = np.zeros((n, 4, 3, 9))  # 3 Gauss points of membrane strains, then the drilling row
    Bb = np.zeros((n, 3, 5, 9))  # curvatures, then the transverse shears
    for g, (xi, eta) in enumerate(_GP):
        dNx = np.einsum("nik,kI->niI", invJ, _quadratic(xi, eta))
        Bm[:, g] = _strain_rows(dNx, U)
        Bb[:, g, :3] = _strain_rows(dNx, Bt)
    points = xl[:, :1] + np.einsum("gk,nki->ngi", _GP, J)
    Bb[:, :, 3:] = _shear_rows(xl, edges, gam, points)
    gx, gy = _gradients(np.einsum("nik,kI->niI", invJ, _quadratic(1 / 3, 1 / 3)), U)
    Bm[:, 3, 0] = -0.5 * (gx[:, 1] - gy[:, 0])  # theta_z - (v,x - u,y) / 2 at the centroid
    Bm[:, 3, 0, 2::3] += 1.0 / 3.0
    lead = np.shape(sec.A)[:-3]  # (n,) for sections rotated per cell
    Cm = np.zeros(lead + (4, 3, 3))  # membrane A at the Gauss points, gamma on the drilling row
    Cm[..., :3, :, :] = sec.A
    Cm[..., 3, 0, 0] = np.reshape(sec.drilling, lead)
    w = np.repeat((area / 3.0)[:, None], 3, axis=1)
    Km = btdb(Bm, Cm, np.column_stack([w, area]))
    Cb = np.zeros(np.shape(sec.D)[:-2] + (5, 5))  # (n, 1, 5, 5) for sections rotated per cell
    Cb[..., :3, :3], Cb[..., 3:, 3:] = sec.D, sec.S
    Kb = btdb(Bb, Cb, w)

    L = np.array([[1 - xi - eta, xi, eta] for xi, eta in _GP])
    Mm, Mb = rotary_mass(L, w, sec)
    return merge(Km, Kb), merge(Mm, Mb + _bciz_w_mass(xl, area, sec.m))


def matrices(xyz: np.ndarray, prop):
    """Global stiffness and mass (n_cells, 18, 18) of tri3 cells with nodes ``xyz`` (n_cells, 3, 3)."""
    xyz = np.asarray(xyz, dtype=float)
    R, xl, _ = local_frame(xyz)
    Kl, Ml = local_matrices(xl, prop, oriented(prop, R))
    return to_global(Kl, R), to_global(Ml, R)
