"""A ribbed plate two ways: the rib as an offset beam on the plate's nodes, and the rib as a fine strip
of shell elements standing on the plate. The first free-free frequencies must agree within 2 %."""

import numpy as np
import pytest

from pcbdyn.fe import BeamProperty, Model, ShellProperty, dof_index
from pcbdyn.fe.modal import solve_modes

E, NU, RHO = 70e9, 0.33, 2700.0  # aluminium
LX, LY, T = 0.200, 0.100, 0.002  # plate
B, H = 0.005, 0.010  # rib width and height, on the plate's top face along x at y = LY / 2
NX, NY, NZ = 40, 20, 8  # plate elements along x and y, strip elements over the rib height


def _grid(nu_, nv):
    """Quad connectivity of an (nu_ + 1) x (nv + 1) structured grid numbered with u fastest."""
    i, j = np.meshgrid(np.arange(nu_), np.arange(nv), indexing="xy")
    a = (j * (nu_ + 1) + i).ravel()
    return np.column_stack([a, a + 1, a + nu_ + 2, a + nu_ + 1])


def _plate():
    x, y = np.meshgrid(np.linspace(0, LX, NX + 1), np.linspace(0, LY, NY + 1), indexing="xy")
    model = Model(np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]))
    model.add("plate", "quad4", _grid(NX, NY), ShellProperty(E=E, nu=NU, rho=RHO, t=T))
    model.free = True
    foot = (NY // 2) * (NX + 1) + np.arange(NX + 1)  # plate nodes under the rib, y = LY / 2
    assert np.allclose(model.nodes[foot, 1], LY / 2)
    return model, foot


def _torsion_constant(a, b):
    """Saint-Venant torsion constant of an a x b rectangle (a >= b), Roark's series approximation."""
    return a * b**3 * (1 / 3 - 0.21 * b / a * (1 - b**4 / (12 * a**4)))


def _beam_rib_model():
    """Rib = beam on the plate nodes, its axis offset by T/2 + H/2 along the plate normal; local y is
    the normal, so Iz (about local z, horizontal) carries the rib's vertical bending."""
    model, foot = _plate()
    A = B * H
    rib = BeamProperty(
        E=E, nu=NU, rho=RHO, A=A, Iy=H * B**3 / 12, Iz=B * H**3 / 12, J=_torsion_constant(H, B),
        orientation=(0.0, 0.0, 1.0), offset=(0.0, 0.0, T / 2 + H / 2),
        shear_area_y=5 / 6 * A, shear_area_z=5 / 6 * A,
    )
    model.add("rib", "beam2", np.column_stack([foot[:-1], foot[1:]]), rib)
    return model


def _shell_rib_model():
    """Rib = vertical shell strip of thickness B from the plate's top face (z = T/2) up to T/2 + H.
    Its foot is tied to the plate's mid-surface nodes through the T/2 lever: u_foot = u_plate +
    theta_plate x (0, 0, T/2), and the rotation about the rib's axis is shared; the strip's drilling
    rotation and its rotation about the vertical stay its own."""
    model, foot = _plate()
    xs = model.nodes[foot, 0]
    zs = T / 2 + np.linspace(0, H, NZ + 1)
    X, Z = np.meshgrid(xs, zs, indexing="xy")
    strip = model.add_nodes(np.column_stack([X.ravel(), np.full(X.size, LY / 2), Z.ravel()]))
    model.add("rib", "quad4", strip[_grid(NX, NZ)], ShellProperty(E=E, nu=NU, rho=RHO, t=B))
    d = T / 2
    for m, s in zip(foot, strip[: NX + 1]):
        um, us = dof_index(m), dof_index(s)
        model.mpcs.append((int(us[0]), [(int(um[0]), 1.0), (int(um[4]), d)]))  # ux + ry d
        model.mpcs.append((int(us[1]), [(int(um[1]), 1.0), (int(um[3]), -d)]))  # uy - rx d
        model.mpcs.append((int(us[2]), [(int(um[2]), 1.0)]))
        model.mpcs.append((int(us[3]), [(int(um[3]), 1.0)]))
    return model


@pytest.fixture(scope="module")
def frequencies():
    out = {}
    for name, build in (("beam", _beam_rib_model), ("shell", _shell_rib_model)):
        modes = solve_modes(build(), n_modes=5)
        assert modes.n_rigid == 6
        out[name] = modes.frequencies
    plain, _ = _plate()
    out["plate"] = solve_modes(plain, n_modes=5).frequencies
    out["beam_no_offset"] = solve_modes(_beam_rib_model().with_property("rib", offset=(0.0, 0.0, 0.0)),
                                        n_modes=5).frequencies
    return out


def test_beam_rib_matches_shell_rib(frequencies):
    fb, fs = frequencies["beam"], frequencies["shell"]
    assert np.max(np.abs(fb / fs - 1)) < 0.02


def test_the_rib_and_its_offset_matter(frequencies):
    """The comparison is only meaningful if the rib changes the plate's modes substantially, and the
    offset is what makes the beam agree: a rib bending about the plate's mid-surface is far softer."""
    assert np.max(np.abs(frequencies["shell"] / frequencies["plate"] - 1)) > 0.2
    assert np.max(np.abs(frequencies["beam_no_offset"] / frequencies["shell"] - 1)) > 0.1
