"""The part models of thesis section 7.2 as functions of the board's quantities.

Each function returns the section property of the board region under a part (and, for the
lumped model, the point mass at its centre) from ``q``, the dictionary of named quantities
(``board.E``, ``components.U1.thickness``, ...), so that a parameter change re-evaluates only
what depends on it.

- lumped: the region keeps the bare board; the part is a point mass at its centre with the
  rotary inertia of a uniform box of the part's footprint and height about the two in-plane axes
  (section 7.2.2). The mass sits on an extra node that follows the footprint's nodes by a
  least-squares plane fit (an interpolation constraint that adds no stiffness): rotary inertia
  on a single shell node would load a point-moment singularity of the Mindlin plate and give
  local modes that keep dropping as the mesh is refined. The inertia about z is left out (it
  would only meet the shells' artificial drilling stiffness).
- spread: the part's mass is spread uniformly over its footprint as non-structural mass of the
  footprint elements (consistent mass, so it reaches the footprint nodes with the element shape
  functions); stiffness stays the board's (section 7.2.2).
- smeared_local: the region gets its own E and density at the board's thickness; by default E is
  the board's and the density carries board + part mass (section 7.2.3).
- equivalent_thickness: the region has thickness T and the density of eq. 7.7,
  rho = (Mc + rho_b Sc Tb) / (T Sc), so the region's mass is board + part whatever T is.
- global smearing (board option ``smear = "global"``): every part's mass is spread over the whole
  board as non-structural mass (section 7.2.3, global mass smearing).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .. import targets
from ..fe import MassProperty, ShellProperty


#: the quantity that multiplies every shell's transverse shear stiffness (1: the laminate's own
#: estimate, 5/6 G t of the isotropic board): a glass-epoxy board's interlaminar shear modulus is
#: rarely known, and it sets the twisting modes near free edges (a Kirchhoff plate is its limit)
SHEAR_KEY = "board.transverse_shear"


def board_keys(board) -> tuple:
    """Quantities the bare board's property depends on."""
    return (("board.E", "board.rho", "board.thickness") if board.isotropic is not None else ()) + (SHEAR_KEY,)


def _sheared(prop, q: dict):
    return replace(prop, shear_factor=prop.shear_factor * q.get(SHEAR_KEY, 1.0))


def base_property(board, q: dict, nsm: float = 0.0):
    """The bare board's shell property (isotropic material or equivalent laminate)."""
    if board.isotropic is not None:
        m = board.isotropic
        return _sheared(ShellProperty(q["board.E"], m.nu, q["board.rho"], q["board.thickness"], nsm=nsm), q)
    return _sheared(replace(board.plate, nsm=board.plate.nsm + nsm), q)


def board_isotropic(board, q: dict):
    """(E, nu, mass per area, thickness) of the bare board as a homogeneous plate."""
    p = base_property(board, q)
    if board.isotropic is not None:
        return q["board.E"], board.isotropic.nu, p.mass_per_area(), p.t
    E, nu = board.plate.equivalent_isotropic()
    return E, nu, p.mass_per_area(), p.t


def global_nsm(board) -> float:
    """Non-structural mass per area [kg/m^2] that spreads all parts over the board (smear = global)."""
    if board.smear != "global":
        return 0.0
    return sum(c.mass for c in board.components) / board.outline.area()


def _key(c, attribute: str) -> str:
    """The target ``components.<ref>.<attribute>`` of part ``c``."""
    return targets.target("components", c.ref, attribute)


def region_keys(board, c) -> tuple:
    own = {
        "lumped": (),
        "spread": (_key(c, "mass"),),
        "smeared_local": (_key(c, "E"), _key(c, "rho")),
        "equivalent_thickness": (_key(c, "thickness"), _key(c, "mass")),
    }[c.model]
    if c.model == "smeared_local":  # its own E and density, at the board's thickness
        shared = (SHEAR_KEY,) + (("board.thickness",) if board.isotropic is not None else ())
    else:
        shared = board_keys(board)
    return shared + own


def region_property(board, c, q: dict):
    """Shell property of the elements under part ``c``."""
    if c.model == "lumped":
        return base_property(board, q)
    if c.model == "spread":
        return base_property(board, q, nsm=q[_key(c, "mass")] / c.area)
    E, nu, m_b, t_b = board_isotropic(board, q)
    if c.model == "smeared_local":
        return _sheared(ShellProperty(q[_key(c, "E")], nu, q[_key(c, "rho")], t_b), q)
    T = q[_key(c, "thickness")]
    rho = (q[_key(c, "mass")] + m_b * c.area) / (T * c.area)  # eq. 7.7
    return _sheared(ShellProperty(E, nu, rho, T), q)


def lumped_mass(c, q: dict) -> MassProperty:
    """Point mass of a lumped part with the in-plane-axis rotary inertia of a uniform a x b x h box."""
    m = q[_key(c, "mass")]
    a, b = c.size
    h = c.height
    return MassProperty(m, (m * (b**2 + h**2) / 12.0, m * (a**2 + h**2) / 12.0, 0.0))


def initial_quantities(board) -> dict:
    """Starting values of every component quantity a parameter may address."""
    q = {}
    if board.smear == "global":
        return q
    for c in board.components:
        q[_key(c, "mass")] = c.mass
        if c.model == "equivalent_thickness":
            q[_key(c, "thickness")] = c.thickness
        if c.model == "smeared_local":
            E = board.quantity(_key(c, "E"))
            q[_key(c, "E")] = E if E is not None else (c.E if c.E is not None else board.plate.equivalent_isotropic()[0])
            q[_key(c, "rho")] = board.quantity(_key(c, "rho"))
    return q


def follow_footprint(model, centre: int, nodes) -> None:
    """Constrain node ``centre`` to the least-squares rigid motion of ``nodes``: in-plane
    translations to their mean, w and the two tilts to the plane fitted through their w."""
    from ..fe import dof_index

    nodes = np.asarray(nodes)
    d = model.nodes[nodes, :2] - model.nodes[centre, :2]
    P = np.linalg.pinv(np.c_[np.ones(len(nodes)), d])  # rows: w at centre, dw/dx, dw/dy
    dofs = dof_index(nodes)
    c = dof_index(centre)
    mean = 1.0 / len(nodes)
    model.mpcs.append((int(c[0]), [(int(k), mean) for k in dofs[:, 0]]))
    model.mpcs.append((int(c[1]), [(int(k), mean) for k in dofs[:, 1]]))
    model.mpcs.append((int(c[2]), [(int(k), float(a)) for k, a in zip(dofs[:, 2], P[0])]))
    model.mpcs.append((int(c[3]), [(int(k), float(a)) for k, a in zip(dofs[:, 2], P[2])]))  # theta_x = w,y
    model.mpcs.append((int(c[4]), [(int(k), -float(a)) for k, a in zip(dofs[:, 2], P[1])]))  # theta_y = -w,x
