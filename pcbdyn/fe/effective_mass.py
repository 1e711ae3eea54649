"""Effective modal mass: the share of a structure's mass (or rotary inertia) that each mode carries
when the structure is moved rigidly, the measure of which modes a base excitation or a shock drives.

With mass-normalised modes phi_r (phi_r^T M phi_r = 1) and r_k the unit rigid-body motion k (a
translation along x, y or z, or a unit rotation about the x, y or z axis through the centre of
mass), the participation factor is Gamma_rk = phi_r^T M r_k and the effective mass Gamma_rk^2,
compared with the rigid-body mass r_k^T M r_k (the mass for a translation, the moment of inertia
about the axis through the centre of mass for a rotation). Over all modes of a model whose
supports carry no mass the shares add to one (the rigid motion expanded in the complete modal
basis); the mass a support holds moves with the base and is no mode's. The elastic modes of a
free structure are mass-orthogonal to its rigid-body modes, which span every r_k: their
effective masses are zero and the rigid-body modes carry it all.

Use (``nodes`` (n, 3) [m], ``M`` the full 6-DOF/node mass matrix, ``shapes`` full-length
mass-normalised columns)::

    em = effective_mass(nodes, M, shapes)
    em.fractions        # (n_modes, 6) shares in AXES order
    em.cumulative       # running sums over the modes
    em.as_dicts()       # [{"x": .., "y": .., "z": .., "rx": .., "ry": .., "rz": ..}] per mode
    em.share("z")       # what all of them carry along z
    shortfall(em, "z", frequencies)   # the note a base-excitation or shock analysis prints, or None
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mesh import NDOF

#: the rigid-body motions, in the order of every array here
AXES = ("x", "y", "z", "rx", "ry", "rz")
#: below this share of the mass moved along an excited axis, the modes used are too few to say nothing
ENOUGH = 0.90


def centre_of_mass(nodes, M) -> np.ndarray:
    """The centre of mass [m] from the mass matrix: m c = r^T M p with r a rigid translation and p
    the same translation's DOFs set to the nodes' coordinates (shape functions reproduce linear
    fields, so r^T M p is the first moment of the mass). Translations along z give c_x, c_y; along
    x, c_z (a flat board's out-of-plane mass is the one it surely has)."""
    nodes = np.asarray(nodes, dtype=float)
    c = np.zeros(3)
    for coord, axis in ((0, 2), (1, 2), (2, 0)):
        r = np.zeros(M.shape[0])
        r[axis::NDOF] = 1.0
        p = np.zeros(M.shape[0])
        p[axis::NDOF] = nodes[:, coord]
        Mr = M @ r
        c[coord] = float(Mr @ p) / float(Mr @ r)
    return c


def rigid_body_vectors(nodes, centre) -> np.ndarray:
    """(n_dof, 6): unit translations along x, y, z and unit rotations about the axes x, y, z through
    ``centre`` (u = theta x (p - centre), the node rotations theta), 6 DOFs per node."""
    d = np.asarray(nodes, dtype=float) - np.asarray(centre, dtype=float)
    n = d.shape[0]
    R = np.zeros((n, NDOF, 6))
    for k in range(3):
        R[:, k, k] = 1.0
        axis = np.zeros(3)
        axis[k] = 1.0
        R[:, :3, 3 + k] = np.cross(axis, d)
        R[:, 3 + k, 3 + k] = 1.0
    return R.reshape(n * NDOF, 6)


@dataclass(frozen=True)
class EffectiveMass:
    """Effective masses of ``n_modes`` modes in :data:`AXES` order: ``participation`` Gamma
    (n_modes, 6) [kg^0.5, kg^0.5 m], ``totals`` the rigid-body mass [kg] and moments of inertia
    about the axes through ``centre`` [kg m^2] (6,), ``centre`` the centre of mass [m]."""

    participation: np.ndarray
    totals: np.ndarray
    centre: np.ndarray

    @property
    def masses(self) -> np.ndarray:
        """Gamma^2 (n_modes, 6): effective masses [kg] and effective moments of inertia [kg m^2]."""
        return self.participation**2

    @property
    def fractions(self) -> np.ndarray:
        """Gamma^2 / (r^T M r) (n_modes, 6): each mode's share of the rigid-body mass or inertia."""
        return self.masses / np.where(self.totals > 0, self.totals, np.inf)

    @property
    def cumulative(self) -> np.ndarray:
        """Running sums of :attr:`fractions` over the modes (n_modes, 6)."""
        return np.cumsum(self.fractions, axis=0)

    def share(self, axis: str) -> float:
        """The share all the modes carry along ``axis`` (one of :data:`AXES`); 0 without modes."""
        return float(self.fractions[:, AXES.index(axis)].sum())

    def as_dicts(self) -> list:
        """One {"x", "y", "z", "rx", "ry", "rz"} dict of fractions per mode (the JSON contract
        ``modes[].effective_mass``)."""
        return [{a: float(v) for a, v in zip(AXES, row)} for row in self.fractions]


def shortfall(em: EffectiveMass, axis: str, frequencies, enough: float = ENOUGH) -> str | None:
    """The note an analysis by modal superposition along ``axis`` prints when its modes (of
    ``frequencies`` [Hz]) carry less than ``enough`` of the mass moved along it; None when they carry
    enough."""
    share = em.share(axis)
    if share >= enough:
        return None
    top = f" (up to {max(frequencies):.0f} Hz)" if len(frequencies) else ""
    n = len(frequencies)
    return (f"the {n} mode{'' if n == 1 else 's'} used{top} carry {100 * share:.1f} % of the mass moved along {axis} "
            f"(< {100 * enough:.0f} %): the rest, in higher modes and at the supports, is missing from the modal "
            "sum")


def effective_mass(nodes, M, shapes) -> EffectiveMass:
    """The :class:`EffectiveMass` of the mass-normalised full-length ``shapes`` (n_dof, n_modes) of
    a model with ``nodes`` (n, 3) [m] and full mass matrix ``M`` (n_dof, n_dof)."""
    if M.shape[0] != NDOF * len(nodes):
        raise ValueError(f"M has {M.shape[0]} rows for {len(nodes)} nodes: pass the full 6-DOF/node mass matrix")
    centre = centre_of_mass(nodes, M)
    R = rigid_body_vectors(nodes, centre)
    MR = np.asarray(M @ R)
    shapes = np.asarray(shapes).reshape(M.shape[0], -1)
    return EffectiveMass(shapes.T @ MR, np.einsum("ik,ik->k", R, MR), centre)
