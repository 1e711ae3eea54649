"""The FE model of a box: one conforming mesh (plates share the nodes of the edges they share, ribs follow
element edges), the mass it carries, supports and orthotropic plates against Navier's solutions, joints
between rigid and hinged, and parameter derivatives that match models rebuilt from edited files."""

import numpy as np
import pytest

from pcbdyn.box import load_box
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import solve_modes

from box_helpers import EXAMPLE, edited, plate_box, supports

E, NU, RHO = 70e9, 0.33, 2700.0


def test_plates_share_the_nodes_of_their_edges_and_ribs_follow_element_edges():
    box = load_box(EXAMPLE)
    pm = box.build(mesh_size=0.012)
    mesh = pm.mesh
    for c in box.contacts:
        a, b = (mesh.plate_nodes(n) for n in c.plates)
        chain = mesh.chain(c.start, c.end)  # a line of element edges ...
        assert chain.size >= c.length / 0.012 and np.isin(chain, a).all() and np.isin(chain, b).all()  # ... of both
    for r in box.ribs:
        plate = box.plate(r.plate)
        chain = mesh.chain(plate.point(*r.start), plate.point(*r.end), mesh.plate_nodes(plate.name))
        rib = pm.model.sets[f"ribs.{r.name}"]
        assert rib.etype == "beam2" and np.array_equal(rib.conn, np.column_stack([chain[:-1], chain[1:]]))
        assert np.allclose(rib.prop.offset, -plate.normal * 6e-3 if r.side == "-n" else plate.normal * 6e-3)


def test_the_model_carries_the_mass_of_plates_ribs_and_relay_in_every_direction():
    box = load_box(EXAMPLE)
    pm = box.build(mesh_size=0.015)
    _, M = assemble(pm.model)
    plates = sum(RHO * p.thickness * p.lengths[0] * p.lengths[1] for p in box.plates)
    ribs = sum(RHO * r.height * r.width * np.linalg.norm(np.subtract(r.end, r.start)) for r in box.ribs)
    for k in range(3):
        t = np.zeros(pm.model.n_dof)
        t[k::6] = 1.0
        assert t @ M @ t == pytest.approx(plates + ribs + 0.080, rel=1e-10)


def navier(D11, D22, D12, D66, rho_t, a, b, n=4):
    """First ``n`` frequencies [Hz] of a simply supported orthotropic plate a x b (D11 along a)."""
    f = [np.pi**2 / (2 * np.pi) * np.sqrt((D11 * (i / a) ** 4 + 2 * (D12 + 2 * D66) * (i / a) ** 2 * (j / b) ** 2
                                           + D22 * (j / b) ** 4) / rho_t) for i in range(1, 5) for j in range(1, 5)]
    return np.sort(f)[:n]


def test_a_plate_hinged_on_its_edges_matches_navier(tmp_path):
    t = 2e-3
    box = load_box(plate_box(tmp_path, 200, 120, 2, supports("p", "hinged"), mesh_mm=5))
    D = E * t**3 / (12 * (1 - NU**2))
    f = solve_modes(box.build().model, n_modes=4).frequencies
    np.testing.assert_allclose(f, navier(D, D, NU * D, (1 - NU) / 2 * D, RHO * t, 0.2, 0.12), rtol=0.01)


@pytest.mark.parametrize("turn_deg", [0.0, 30.0])
def test_an_orthotropic_plate_matches_navier_however_it_lies(tmp_path, turn_deg):
    """Eu = 70 GPa along u, Ev = 35 GPa across: the element frames of the unstructured mesh lie at every
    angle to u, so the moduli must be turned into each of them."""
    t, Eu, Ev = 2e-3, 70e9, 35e9
    c, s = np.cos(np.radians(turn_deg)), np.sin(np.radians(turn_deg))
    path = plate_box(tmp_path, 200, 120, 2, supports("p", "hinged"), mesh_mm=5,
                     material='E = ["70 GPa", "35 GPa"]\nnu = 0.3\nrho = "2700 kg/m^3"')
    text = path.read_text().replace('u = ["200 mm", "0 mm", "0 mm"]', f'u = ["{200 * c} mm", "{200 * s} mm", "0 mm"]')
    path.write_text(text.replace('v = ["0 mm", "120 mm", "0 mm"]', f'v = ["{-120 * s} mm", "{120 * c} mm", "0 mm"]'))
    box = load_box(path)
    assert box.plate("p").material.orthotropic
    d = 1 - 0.3 * 0.3 * Ev / Eu
    k = t**3 / 12
    G = np.sqrt(Eu * Ev) / (2 * 1.3)
    expected = navier(Eu * k / d, Ev * k / d, 0.3 * Ev * k / d, G * k, RHO * t, 0.2, 0.12)
    np.testing.assert_allclose(solve_modes(box.build().model, n_modes=4).frequencies, expected, rtol=0.01)


def test_joints_lie_between_rigid_and_hinged_edges(tmp_path):
    def modes(k_rot):
        path = edited(tmp_path, remove=("parameters",), name=f"j{k_rot}.toml")
        if k_rot is not None:
            path.write_text(path.read_text() + "".join(
                f'\n[[joints]]\nname = "j_{p}"\nplates = ["upper", "{p}"]\nk_rot = "{k_rot} N*m/rad/m"\n'
                for p in ("left", "right", "back")))
        return solve_modes(load_box(path).build(mesh_size=0.02).model, n_modes=6).frequencies

    rigid, stiff, soft, loose = modes(None), modes(1e10), modes(1e3), modes(1e-3)
    np.testing.assert_allclose(stiff, rigid, rtol=2e-4)
    assert np.all(loose < soft) and np.all(soft < rigid) and loose[0] < 0.85 * rigid[0]


def test_a_box_without_supports_floats(tmp_path):
    modes = solve_modes(load_box(edited(tmp_path, remove=("supports",))).build(mesh_size=0.025).model, n_modes=4)
    assert modes.n_rigid == 6 and modes.frequencies[0] > 50


@pytest.mark.parametrize("parameter, target, rel", [("h_side", "ribs.{}.height", 1e-3),
                                                    ("t_left", "plates.left.thickness", 1e-3),
                                                    ("rho_upper", "plates.upper.rho", 1e-3)])
def test_parameter_derivatives_match_models_rebuilt_from_edited_files(tmp_path, parameter, target, rel):
    """dK/dp, dM/dp of a parameter (from the element sets it touches) against the central difference of the
    whole model built afresh from files with the value changed: nothing that depends on it is missed (a
    plate's thickness also moves its ribs' axes)."""
    path = edited(tmp_path)
    if parameter == "t_left":
        path.write_text(path.read_text() + '\n[[parameters]]\nname = "t_left"\ntarget = "plates.left.thickness"\n'
                                           'bounds = ["1 mm", "4 mm"]\n')
    box = load_box(path)
    pm = box.build(mesh_size=0.025)
    par = pm.parameters[parameter]
    dK, dM = par.derivatives(pm)
    p0 = par.value
    rebuilt = []
    for sign in (1, -1):
        p = p0 * (1 + sign * rel)
        rebuilt.append(assemble(load_box(box.write_updated({parameter: p}, tmp_path / f"x{sign}.toml")).build(
            mesh_size=0.025).model))
    for k, d in ((0, dK), (1, dM)):
        fd = (rebuilt[0][k] - rebuilt[1][k]) / (2 * rel * p0)
        assert abs(fd - d).max() <= 1e-5 * max(abs(fd).max(), 1e-300)
