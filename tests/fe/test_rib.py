"""A ribbed plate three ways: the rib as an offset beam on the plate's nodes, as a fine strip of shell
elements standing on the plate, and as an offset beam embedded in the plate along a line no node
row follows. The first free-free frequencies must agree within 2 % (the embedded rib: 2.5 %, within
1 % once the plate is meshed twice as fine across)."""

import numpy as np
import pytest

from pcbdyn.fe import BeamProperty, EmbeddedBeamProperty, Model, ShellProperty, dof_index
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


def _plate(ny=NY):
    x, y = np.meshgrid(np.linspace(0, LX, NX + 1), np.linspace(0, LY, ny + 1), indexing="xy")
    model = Model(np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]))
    model.add("plate", "quad4", _grid(NX, ny), ShellProperty(E=E, nu=NU, rho=RHO, t=T))
    model.free = True
    foot = (ny // 2) * (NX + 1) + np.arange(NX + 1)  # plate nodes under the rib, y = LY / 2 (ny even)
    return model, foot


def _torsion_constant(a, b):
    """Saint-Venant torsion constant of an a x b rectangle (a >= b), Roark's series approximation."""
    return a * b**3 * (1 / 3 - 0.21 * b / a * (1 - b**4 / (12 * a**4)))


def _rib():
    """The rib's section, its axis offset by T/2 + H/2 along the plate normal; local y is the normal,
    so Iz (about local z, horizontal) carries the rib's vertical bending."""
    A = B * H
    return BeamProperty(
        E=E, nu=NU, rho=RHO, A=A, Iy=H * B**3 / 12, Iz=B * H**3 / 12, J=_torsion_constant(H, B),
        orientation=(0.0, 0.0, 1.0), offset=(0.0, 0.0, T / 2 + H / 2),
        shear_area_y=5 / 6 * A, shear_area_z=5 / 6 * A,
    )


def _beam_rib_model():
    """Rib = beam on the plate nodes."""
    model, foot = _plate()
    assert np.allclose(model.nodes[foot, 1], LY / 2)
    model.add("rib", "beam2", np.column_stack([foot[:-1], foot[1:]]), _rib())
    return model


def _embedded_rib_model(ny=NY - 3):
    """Rib = beam embedded in a plate meshed with ``ny`` (odd: no node row at y = LY / 2) elements
    across, in pieces of half an element whose ends are located in the plate's cells."""
    from pcbdyn.fe.probe import locate

    model, _ = _plate(ny)
    n = 2 * NX
    pts = np.column_stack([np.linspace(0, LX, n + 1), np.full(n + 1, LY / 2), np.zeros(n + 1)])
    loc = locate(model.nodes, [("quad4", model.sets["plate"].conn)], pts)
    assert loc.found.all()
    W = np.zeros((n, 2, 8))
    W[:, 0, :4], W[:, 1, 4:] = loc.weights[:-1], loc.weights[1:]
    model.add("rib", "embedded_beam2", np.hstack([loc.nodes[:-1], loc.nodes[1:]]), EmbeddedBeamProperty(_rib(), W))
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
    for name, build in (("beam", _beam_rib_model), ("shell", _shell_rib_model), ("embedded", _embedded_rib_model),
                        ("embedded_fine", lambda: _embedded_rib_model(2 * NY + 1))):
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


def test_embedded_rib_off_the_node_rows_matches_the_shell_rib(frequencies):
    """Tied to the cells' interpolated motion the rib is a little stiff on a coarse mesh (2.4 % on
    mode 3 with 17 elements across) and converges as the mesh is refined."""
    coarse = np.abs(frequencies["embedded"] / frequencies["shell"] - 1)
    fine = np.abs(frequencies["embedded_fine"] / frequencies["shell"] - 1)
    assert coarse.max() < 0.025 and fine.max() < 0.01 and fine.max() < 0.5 * coarse.max()


def test_embedded_rib_carries_its_mass_and_no_rigid_motion_strain():
    """Its ends follow the plate's interpolated motion: a rigid translation carries rho A L, rigid
    motions strain nothing."""
    from pcbdyn.fe.assembly import assemble

    model = _embedded_rib_model()
    K, M = assemble(model, sets=["rib"])
    n = model.nodes.shape[0]
    x = model.nodes - model.nodes.mean(0)
    rigid = np.zeros((6 * n, 6))
    for a in range(3):
        rigid[a::6, a] = 1.0
        axis = np.eye(3)[a]
        rot = np.zeros((n, 6))
        rot[:, :3], rot[:, 3:] = np.cross(axis, x), axis
        rigid[:, 3 + a] = rot.ravel()
    for a in range(3):
        assert rigid[:, a] @ M @ rigid[:, a] == pytest.approx(RHO * B * H * LX, rel=1e-10)
    assert np.abs(K @ rigid).max() < 1e-6 * abs(K).max()


def test_the_rib_and_its_offset_matter(frequencies):
    """The comparison is only meaningful if the rib changes the plate's modes substantially, and the
    offset is what makes the beam agree: a rib bending about the plate's mid-surface is far softer."""
    assert np.max(np.abs(frequencies["shell"] / frequencies["plate"] - 1)) > 0.2
    assert np.max(np.abs(frequencies["beam_no_offset"] / frequencies["shell"] - 1)) > 0.1


def test_chunked_assembly_and_set_values_equal_one_piece(monkeypatch):
    """Assembly and :class:`SetAssembly` values computed a few cells at a time (per-cell data of the
    embedded rib sliced with them) equal the same sums made in one piece."""
    from pcbdyn.fe import assembly

    model = _embedded_rib_model()
    K1, M1 = assembly.assemble(model)
    one = assembly.SetAssembly(model)
    whole = {nm: one.values(nm) for nm in one.names}
    monkeypatch.setattr(assembly, "CHUNK_CELLS", 3)
    assert all(len(model.sets[nm].conn) > 3 for nm in one.names)
    K3, M3 = assembly.assemble(model)
    for A, B in ((K1, K3), (M1, M3)):
        np.testing.assert_allclose(B.toarray(), A.toarray(), rtol=0, atol=1e-12 * abs(A).max())
    chunked = assembly.SetAssembly(model)
    for nm in chunked.names:
        for a, b in zip(whole[nm], chunked.values(nm)):
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * np.abs(a).max())
