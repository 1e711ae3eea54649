"""What the flat shell elements share: the section data, the element frame (with the rigid-link
correction of warped quads), the rotation of element matrices to global axes, the B^T C B sum,
the drilling penalty, the membrane/bending block layout and the bilinear/linear part of the mass.

Local DOF order per node is the global one, (u, v, w, theta_x, theta_y, theta_z), but in the
element frame (x, y in the mid-plane, z along the normal). Rotations follow the right-hand rule,
so the normal's tilt is beta_x = theta_y, beta_y = -theta_x (u = z beta_x, v = z beta_y).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import ModelError

#: Drilling stiffness gamma = DRILLING_PENALTY * (in-plane shear stiffness G t) on
#: (theta_z - in-plane rotation)^2 (Hughes & Brezzi 1989). Hughes and Brezzi allow any
#: gamma > 0; a small one keeps in-plane bending of distorted elements free of locking and
#: adds little rotational stiffness where a plate meets another at an angle (there the drilling
#: rotation of one is a bending rotation of the other): for element size h and thickness t the
#: added stiffness relative to the plate bending stiffness there is about
#: 5 * DRILLING_PENALTY * (h/t)^2 (0.1 for h = 5 t). It has no effect on flat plates.
DRILLING_PENALTY = 1e-3


@dataclass(frozen=True)
class Section:
    """Stress-resultant matrices and inertias per unit area of one shell property."""

    A: np.ndarray  # membrane (3, 3) [N/m]
    D: np.ndarray  # bending (3, 3) [N m]
    S: np.ndarray  # transverse shear (2, 2) [N/m]
    m: float  # translational mass [kg/m^2]
    I: float  # rotary inertia [kg]

    @property
    def drilling(self) -> float:
        """The drilling penalty gamma [N/m]: a fraction of the in-plane shear stiffness A66."""
        return DRILLING_PENALTY * self.A[..., 2, 2]


def section(prop) -> Section:
    """The section of a shell property (any object with membrane/bending/shear/mass_per_area/
    rotary_inertia_per_area), checked so that a bad value is named before it spoils a solve."""
    mats = {}
    for name, shape in (("membrane", (3, 3)), ("bending", (3, 3)), ("shear", (2, 2))):
        a = np.asarray(getattr(prop, name)(), dtype=float)
        if a.shape != shape or not np.allclose(a, a.T, rtol=1e-10, atol=0.0):
            raise ModelError(f"shell property {name}() must be a symmetric {shape[0]}x{shape[1]} matrix")
        if np.linalg.eigvalsh(a).min() <= 0.0:
            raise ModelError(
                f"shell property {name}() is not positive definite: check E > 0, -1 < nu < 0.5 and t > 0"
            )
        mats[name] = a
    m = float(prop.mass_per_area())
    inertia = float(prop.rotary_inertia_per_area())
    if not m > 0.0:
        raise ModelError(f"shell property mass_per_area() must be > 0 (rho * t + nsm), got {m}")
    if not inertia >= 0.0:
        raise ModelError(f"shell property rotary_inertia_per_area() must be >= 0, got {inertia}")
    return Section(mats["membrane"], mats["bending"], mats["shear"], m, inertia)


def oriented(prop, R: np.ndarray) -> Section:
    """The section of ``prop`` for cells whose frames are ``R`` (n, 3, 3): :func:`section`, or for a
    property with a material ``axis`` (its matrices given with x along that axis) the matrices rotated
    into each element's frame, shaped (n, 1, ., .) to broadcast over Gauss points. With c, s the
    axis' components along e1, e2, the material strains are T eps (T = [[c^2, s^2, cs], [s^2, c^2, -cs],
    [-2cs, 2cs, c^2 - s^2]], engineering shear) and the transverse shears Q gamma (Q = [[c, s], [-s, c]]),
    so A_e = T^T A T, D_e = T^T D T, S_e = Q^T S Q."""
    sec = section(prop)
    axis = getattr(prop, "axis", None)
    if axis is None:
        return sec
    c, s = R[:, 0] @ np.asarray(axis, float), R[:, 1] @ np.asarray(axis, float)
    norm = np.hypot(c, s)
    if np.any(norm < 1e-6 * np.linalg.norm(axis)):
        raise ModelError("a shell property's material axis is normal to some cells: give an axis in their plane")
    c, s = c / norm, s / norm
    T = np.stack([np.stack([c * c, s * s, c * s], -1), np.stack([s * s, c * c, -c * s], -1),
                  np.stack([-2 * c * s, 2 * c * s, c * c - s * s], -1)], 1)
    Q = np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], 1)

    def turn(M, X):
        return np.matmul(X.transpose(0, 2, 1), np.matmul(M, X))[:, None]

    return Section(turn(sec.A, T), turn(sec.D, T), turn(sec.S, Q), sec.m, sec.I)


def local_frame(xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Element frames, in-plane node coordinates and node heights above the mean plane.

    Returns R (n, 3, 3), rows e1, e2, e3 in global axes; the node coordinates (n, npc, 2) in
    that frame about the cell centroid; and the heights h (n, npc) of the nodes above the plane
    through the centroid (zero for triangles and flat quads). e3 is the normal of the mean plane
    (triangles: the plane; quads: the cross product of the diagonals), so node order is
    counter-clockwise about it. e1 follows the first side (triangles) or the mean of sides 1-2
    and 4-3 (quads).
    """
    if xyz.shape[1] == 4:
        normal = np.cross(xyz[:, 2] - xyz[:, 0], xyz[:, 3] - xyz[:, 1])
        e1 = xyz[:, 1] + xyz[:, 2] - xyz[:, 0] - xyz[:, 3]
    else:
        normal = np.cross(xyz[:, 1] - xyz[:, 0], xyz[:, 2] - xyz[:, 0])
        e1 = xyz[:, 1] - xyz[:, 0]
    rel = xyz - xyz.mean(axis=1, keepdims=True)
    size = np.linalg.norm(rel, axis=2).max(axis=1)
    area2 = np.linalg.norm(normal, axis=1)
    bad = ~(area2 > 1e-12 * size**2)
    if bad.any():
        raise ModelError(f"shell cells {np.flatnonzero(bad)[:5].tolist()} are degenerate (zero area)")
    e3 = normal / area2[:, None]
    e1 = e1 - np.einsum("ni,ni->n", e1, e3)[:, None] * e3
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(e3, e1)
    R = np.stack([e1, e2, e3], axis=1)
    local = np.einsum("nij,naj->nai", R, rel)
    h = np.where(np.abs(local[:, :, 2]) > 1e-12 * size[:, None], local[:, :, 2], 0.0)  # flat: exactly 0
    return R, local[:, :, :2], h


def rigid_offsets(Al: np.ndarray, h: np.ndarray) -> np.ndarray:
    """W^T Al W for an element formed on the nodes projected onto its mean plane (warped quads).

    Each projected point is tied rigidly to its node at height h above it: its displacement is
    u + theta x (0, 0, -h), i.e. u - h theta_y, v + h theta_x (element axes). A rigid motion of
    the nodes is a rigid motion of the projected points, so the six rigid-body modes stay
    exact (MacNeal's rigid-link warping correction); without it a warped mesh has spurious
    low-frequency modes. Membrane-bending coupling from warping is otherwise not modelled: keep
    the warp (h) small compared to the element size.
    """
    if not np.any(h):
        return Al
    AW = Al.copy()
    AW[:, :, 4::6] -= Al[:, :, 0::6] * h[:, None, :]
    AW[:, :, 3::6] += Al[:, :, 1::6] * h[:, None, :]
    out = AW.copy()
    out[:, 4::6, :] -= AW[:, 0::6, :] * h[:, :, None]
    out[:, 3::6, :] += AW[:, 1::6, :] * h[:, :, None]
    return out


def to_global(Kl: np.ndarray, R: np.ndarray) -> np.ndarray:
    """T^T Kl T with T = blockdiag(R, R, ...) (translations and rotations of every node)."""
    n, nd, _ = Kl.shape
    X = np.matmul(Kl.reshape(n, nd * nd // 3, 3), R).reshape(n, nd, nd)  # Kl T
    Xt = np.ascontiguousarray(X.transpose(0, 2, 1)).reshape(n, nd * nd // 3, 3)
    return np.matmul(Xt, R).reshape(n, nd, nd).transpose(0, 2, 1)  # (T^T Kl T)^T = T^T Kl T


#: local DOFs (per node) of the membrane block (u, v, theta_z) and of the bending block (w, theta_x, theta_y)
MEMBRANE_DOFS = (0, 1, 5)
BENDING_DOFS = (2, 3, 4)


def merge(Am: np.ndarray, Ab: np.ndarray) -> np.ndarray:
    """Element-axes matrix (n, 6 npc, 6 npc) from its uncoupled membrane and bending blocks
    (n, 3 npc, 3 npc), each ordered node by node with the DOFs of MEMBRANE_DOFS / BENDING_DOFS."""
    n, k, _ = Am.shape
    npc = k // 3
    out = np.zeros((n, npc, 6, npc, 6))
    for block, dofs in ((Am, MEMBRANE_DOFS), (Ab, BENDING_DOFS)):
        b5 = block.reshape(n, npc, 3, npc, 3)
        for i, di in enumerate(dofs):
            for j, dj in enumerate(dofs):
                out[:, :, di, :, dj] = b5[:, :, i, :, j]
    return out.reshape(n, 6 * npc, 6 * npc)


def btdb(B: np.ndarray, C: np.ndarray, w: np.ndarray) -> np.ndarray:
    """sum_g w_g B_g^T C_g B_g for strain rows B (n, g, s, d), material C (s, s) or one per
    point (g, s, s), weights w (n, g)."""
    n, g, s, d = B.shape
    CB = np.matmul(C, B) * w[:, :, None, None]
    return np.matmul(B.reshape(n, g * s, d).transpose(0, 2, 1), CB.reshape(n, g * s, d))


def rotary_mass(N: np.ndarray, wdet: np.ndarray, sec: Section) -> tuple[np.ndarray, np.ndarray]:
    """Consistent membrane-block mass (u, v: m; theta_z: I) and the rotary inertia of the
    bending block (w: 0; theta_x, theta_y: I), each (n, 3 npc, 3 npc), from shape values
    N (g, npc) and weights w |J| (n, g). The bending block's w mass comes from the element.

    m = rho t + nsm; I = rho t^3 / 12 is the Mindlin rotary inertia on the two bending
    rotations. The drilling rotation has no inertia of its own: it gets a stand-in that keeps M
    positive definite, DRILLING_PENALTY * I, the same fraction of I as its stiffness gamma is of
    A66, so that its modes sit at omega^2 = A66 / I = 12 G / (rho t^2), the plate's
    thickness-shear frequency, where plate theory ends anyway. With I itself they sat
    1 / sqrt(DRILLING_PENALTY) = 32 times lower, inside the band for thick sections: a 3 mm card
    with parts meshed as thick shells had 415 drilling modes below its 20th bending mode
    (5.4 kHz), clustered at 3.61 kHz, where they took 6 of the 20 modes asked for and made each
    solve 5 times slower.
    """
    n, npc = wdet.shape[0], N.shape[1]
    Ms = (wdet @ np.einsum("ga,gb->gab", N, N).reshape(N.shape[0], -1)).reshape(n, npc, 1, npc, 1)
    mem = np.diag([sec.m, sec.m, DRILLING_PENALTY * sec.I])
    bend = np.diag([0.0, sec.I, sec.I])
    return tuple((Ms * d[None, None, :, None, :]).reshape(n, 3 * npc, 3 * npc) for d in (mem, bend))
