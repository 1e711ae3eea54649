"""Ribs on box plates, two ways: an eccentric Timoshenko beam on the plate's nodes along the rib line
(the model that is updated), or a strip of shell elements standing on the plate (the check: a rib
resolved as a wall, as a finer model or another code would have it).

Beam: the rectangular section height x width (A = b h, I about the plate-parallel axis b h^3 / 12,
about the normal h b^3 / 12, Saint-Venant torsion by Roark's series, shear areas 5/6 A), its axis
offset from the plate's mid-surface by t/2 + h/2 along the side's normal and driven rigidly by the
plate's nodes (:mod:`pcbdyn.fe.elements.beam`), as the thesis' BEAM4 ribs on SHELL63 plates
(section 7.5.3) but with the eccentricity and shear kept.

Strip: near-square quads of thickness b from the plate's face (t/2 off the mid-surface) to t/2 + h,
columns at the nodes of the rib line and between them; each foot node follows the plate's edge there
(the linear interpolation of the two nodes, as the shells' edge moves) through the t/2 lever
(u_foot = u_plate + theta_plate x (t/2 m)) and shares its rotation about the rib's axis (the strip's
other rotations stay its own). Strips that cross share their nodes on the line where they meet; a strip
ending on a supported edge is held there as the edge is (as the beam's end node), its other ends are
free (as the beam meets another plate only at its end node): with these ends the two models of the
example box agree within 0.3 % on the first ten modes at 5 mm.
"""

from __future__ import annotations

import math

import numpy as np

from ..fe import BeamProperty, ShellProperty, dof_index

#: rows of strip elements over a rib's height at least, and per element size
STRIP_MIN_ROWS = 4


def torsion_constant(a: float, b: float) -> float:
    """Saint-Venant torsion constant of an a x b rectangle (Roark's series approximation)."""
    a, b = max(a, b), min(a, b)
    return a * b**3 * (1 / 3 - 0.21 * b / a * (1 - b**4 / (12 * a**4)))


def rib_section(E: float, nu: float, rho: float, height: float, width: float, normal, t_plate: float) -> BeamProperty:
    """The beam of a rib of ``height`` x ``width`` [m] standing on a plate of thickness ``t_plate`` on the
    side of ``normal`` (unit, global axes)."""
    A = width * height
    m = np.asarray(normal, float)
    return BeamProperty(E=E, nu=nu, rho=rho, A=A, Iy=height * width**3 / 12, Iz=width * height**3 / 12,
                        J=torsion_constant(height, width), orientation=tuple(m),
                        offset=tuple((t_plate / 2 + height / 2) * m), shear_area_y=5 / 6 * A, shear_area_z=5 / 6 * A)


def strip_rows(height: float, size: float) -> int:
    return max(STRIP_MIN_ROWS, math.ceil(height / size))


def strip_feet(nodes, chain, step: float) -> list:
    """The strip's columns along the plate nodes ``chain``: each a list of (plate node, weight) whose
    linear interpolation is the column's foot; every piece of the chain is split into pieces no longer
    than ``step`` [m] (near-square strip elements: bilinear quads made long lock in in-plane bending)."""
    feet = [[(int(chain[0]), 1.0)]]
    for a, b in zip(chain[:-1], chain[1:]):
        k = max(1, math.ceil(np.linalg.norm(nodes[b] - nodes[a]) / step - 1e-9))
        feet += [[(int(a), 1.0 - j / k), (int(b), j / k)] if j < k else [(int(b), 1.0)] for j in range(1, k + 1)]
    return feet


def strip_cells(rows: int, cols: int) -> np.ndarray:
    """Quads (rows * (cols - 1), 4) of a grid numbered row by row (foot row first)."""
    i, k = np.meshgrid(np.arange(cols - 1), np.arange(rows))
    a = (k * cols + i).ravel()
    return np.column_stack([a, a + 1, a + cols + 1, a + cols])


def tie_foot(model, foot: int, masters, lever, axis) -> None:
    """The strip's foot node follows the plate's edge between its nodes (``masters``: [(node, weight)],
    linear interpolation) through the ``lever`` (3-vector from the plate's mid-surface to the foot):
    u_foot = sum w (u_m + theta_m x lever), and shares the edge's rotation about the rib ``axis`` (unit):
    theta_foot . e = sum w theta_m . e, solved for the foot's rotation component along which e is largest."""
    r, e = np.asarray(lever, float), np.asarray(axis, float)
    f = dof_index(foot)
    cross = np.array([[0.0, r[2], -r[1]], [-r[2], 0.0, r[0]], [r[1], -r[0], 0.0]])  # (theta x r)_i = cross[i] . theta
    for i in range(3):
        terms = [(int(dof_index(m)[i]), w) for m, w in masters]
        terms += [(int(dof_index(m)[3 + j]), w * cross[i, j]) for m, w in masters for j in range(3) if cross[i, j]]
        model.constrain(int(f[i]), terms)
    k = int(np.argmax(np.abs(e)))
    terms = [(int(dof_index(m)[3 + j]), w * e[j] / e[k]) for m, w in masters for j in range(3) if e[j]]
    terms += [(int(f[3 + j]), -e[j] / e[k]) for j in range(3) if j != k and e[j]]
    model.constrain(int(f[3 + k]), terms)


def add_strips(model, strips, size: float) -> tuple:
    """Add the strips [(name, plate node chain, side normal, plate t, height, width, material)] to ``model``
    (nodes, ties); returns ([(set name, conn, ShellProperty)], [(plate node, end column nodes above the
    foot)] of both ends of every strip). Strips that cross share their nodes."""
    coords, layout = [], []
    for _, chain, normal, t, h, _, _ in strips:
        rows = strip_rows(h, size)
        feet = strip_feet(model.nodes, chain, h / rows)
        base = np.array([sum(w * model.nodes[n] for n, w in f) for f in feet])
        levels = t / 2 + h * np.arange(rows + 1) / rows
        coords.append((base[None] + levels[:, None, None] * np.asarray(normal, float)).reshape(-1, 3))
        layout.append((rows, feet))
    allxyz = np.concatenate(coords)
    _, first, inverse = np.unique(np.round(allxyz / 1e-9).astype(np.int64), axis=0, return_index=True,
                                  return_inverse=True)
    ids = model.add_nodes(allxyz[first])[inverse.ravel()]
    out, ends, start, tied = [], [], 0, set()
    for (name, chain, normal, t, h, b, mat), (rows, feet) in zip(strips, layout):
        cols = len(feet)
        mine = ids[start:start + (rows + 1) * cols]
        start += (rows + 1) * cols
        axis = model.nodes[chain[-1]] - model.nodes[chain[0]]
        for masters, foot in zip(feet, mine[:cols]):
            if int(foot) not in tied:
                tie_foot(model, int(foot), masters, t / 2 * np.asarray(normal, float), axis / np.linalg.norm(axis))
                tied.add(int(foot))
        out.append((name, mine[strip_cells(rows, cols)], ShellProperty(mat.E, mat.nu, mat.rho, b)))
        grid = mine.reshape(rows + 1, cols)
        ends += [(int(chain[0]), grid[1:, 0]), (int(chain[-1]), grid[1:, -1])]
    return out, ends


def hold_ends(model, ends, held: dict) -> None:
    """Where a strip ends on a supported edge (``held``: {plate node: support type}) its end column is held
    as the edge is (clamped: every DOF; hinged: translations), as a beam rib's end node is; elsewhere a
    strip's ends are free (a beam rib meets another plate only at its end node)."""
    for foot, column in ends:
        if foot in held:
            model.fix(column, None if held[foot] == "clamped" else (0, 1, 2))
