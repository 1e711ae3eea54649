"""The 3-D beam element: the thesis cantilever (Table 5.3), rigid-body modes, invariance and mass of a
free frame, Timoshenko shear against the analytical simply-supported beam, and section offsets."""


import numpy as np
import pytest
import scipy.linalg as sla

from pcbdyn.fe import BeamProperty, MassProperty, Model, ModelError, dof_index
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.elements.beam import matrices
from pcbdyn.fe.modal import solve_modes

from reference import thesis_case


def _line_model(L, n_el, props, axis=(1.0, 0.0, 0.0)):
    """Nodes along ``axis`` from the origin; ``props`` is a list of (name, element indices, property)."""
    x = np.linspace(0.0, L, n_el + 1)[:, None] * np.asarray(axis)[None, :]
    model = Model(x)
    conn = np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)])
    for name, idx, prop in props:
        model.add(name, "beam2", conn[idx], prop)
    return model


@pytest.fixture(scope="module")
def cantilever_case():
    return thesis_case("T5.3_cantilever_beam")


def _cantilever(case, softened, planar):
    """Thesis Table 5.3 beam: 18 elements, weak-axis bending in the global x-y plane (local z = global z,
    Iz = b h^3 / 12 is the weak axis); elements 5-8 (1-based, from the clamp) softened in "fx"."""
    inp = case["inputs"]
    b, h = inp["b_m"], inp["h_m"]
    n = inp["n_elem"]
    base = BeamProperty(
        E=inp["E_uniform"], nu=0.3, rho=inp["rho"], A=inp["A_m2"], Iy=h * b**3 / 12, Iz=inp["I_m4"],
        J=b * h**3 / 3 * (1 - 0.63 * h / b), orientation=(0.0, 1.0, 0.0), rotary_inertia=False,
    )
    assert base.Iz == pytest.approx(b * h**3 / 12)
    soft = np.zeros(n, dtype=bool)
    if softened:
        soft[4:8] = True
    props = [("uniform", np.flatnonzero(~soft), base)]
    if softened:
        props.append(("soft", np.flatnonzero(soft), BeamProperty(**{**base.__dict__, "E": inp["E_el5_8_exp"]})))
    model = _line_model(inp["L_m"], n, props)
    model.fix(0)
    if planar:  # keep only the in-plane bending DOFs (transverse uy, rotation rz)
        model.fix(np.arange(1, n + 1), ["ux", "uz", "rx", "ry"])
    return model


@pytest.mark.parametrize("row", ["fa", "fx"])
def test_thesis_cantilever_planar(cantilever_case, row):
    """Table 5.3: with only uy and rz free, the first 8 modes are the weak-axis bending modes."""
    model = _cantilever(cantilever_case, softened=row == "fx", planar=True)
    f = solve_modes(model, n_modes=8).frequencies
    thesis = np.array(cantilever_case["thesis"][row])
    recomputed = np.array(cantilever_case["plain_consistent_mass"][row])
    assert np.max(np.abs(f / thesis - 1)) < 5e-4
    # the independent re-computation (same formulation) is printed to 3 decimals
    assert np.max(np.abs(f / recomputed - 1)) < 1e-4


@pytest.mark.parametrize("row", ["fa", "fx"])
def test_thesis_cantilever_as_ansys_solved_it(cantilever_case, row):
    """The thesis' ANSYS run (BEAM4 with rotary inertia, Guyan reduction onto the transverse
    displacements) is reproduced to its printed digits (0.01 Hz) by the section's rotary inertia and a
    static condensation of the rotations."""
    inp = cantilever_case["inputs"]
    model = _cantilever(cantilever_case, softened=row == "fx", planar=True)
    for name in list(model.sets):
        model = model.with_property(name, rotary_inertia=True)
    K, M = assemble(model)
    n = inp["n_elem"]
    w, r = dof_index(np.arange(1, n + 1), "uy").ravel(), dof_index(np.arange(1, n + 1), "rz").ravel()
    K, M = K.toarray(), M.toarray()
    T = np.vstack([np.eye(n), -np.linalg.solve(K[np.ix_(r, r)], K[np.ix_(r, w)])])
    idx = np.concatenate([w, r])
    Kg = T.T @ K[np.ix_(idx, idx)] @ T
    Mg = T.T @ M[np.ix_(idx, idx)] @ T
    f = np.sqrt(sla.eigh(Kg, Mg, eigvals_only=True)[:8]) / (2 * np.pi)
    assert np.max(np.abs(f - np.array(cantilever_case["thesis"][row]))) < 0.01


@pytest.mark.parametrize("row", ["fa", "fx"])
def test_thesis_cantilever_full_3d(cantilever_case, row):
    """The same beam with all 6 DOF free: out-of-plane bending, torsion and axial modes appear too; the
    weak-axis bending modes are those whose kinetic energy is mostly in uy."""
    model = _cantilever(cantilever_case, softened=row == "fx", planar=False)
    _, M = assemble(model)
    modes = solve_modes(model, f_max=1.05 * max(cantilever_case["thesis"][row]))
    phi = modes.shapes
    uy = np.zeros(model.n_dof)
    uy[dof_index(np.arange(model.n_nodes), ["uy", "rz"]).ravel()] = 1.0
    share = np.einsum("im,i,im->m", phi, uy, M @ phi)  # kinetic energy share in the x-y plane
    in_plane = modes.frequencies[share > 0.99]
    assert np.all((share > 0.99) | (share < 0.01))  # the planes decouple
    assert in_plane.size == 8
    thesis = np.array(cantilever_case["thesis"][row])
    assert np.max(np.abs(in_plane / thesis - 1)) < 5e-4
    assert modes.frequencies.size > 8  # other families are present


def _frame(rotation=np.eye(3), n_el=3):
    """A non-planar free frame of three members with different sections, orientation vectors and one
    offset member, plus a point mass; everything rotated by ``rotation``."""
    corners = np.array([[0.0, 0.0, 0.0], [0.4, 0.0, 0.0], [0.4, 0.3, 0.1], [0.1, 0.35, 0.5]])
    nodes, members = [], []
    for a, b in zip(corners[:-1], corners[1:]):
        start = len(nodes) - 1 if nodes else None
        pts = a + np.linspace(0, 1, n_el + 1)[:, None] * (b - a)
        if start is None:
            nodes.extend(pts)
            first = 0
        else:
            nodes.extend(pts[1:])
            first = start
        members.append(np.column_stack([np.arange(first, first + n_el), np.arange(first + 1, first + n_el + 1)]))
    nodes = np.asarray(nodes) @ rotation.T
    model = Model(nodes)
    model.free = True
    base = dict(E=70e9, nu=0.33, rho=2700.0)
    secs = [
        BeamProperty(**base, A=2e-4, Iy=3e-9, Iz=1e-9, J=2e-9, orientation=(0.0, 0.0, 1.0)),
        BeamProperty(**base, A=1.5e-4, Iy=2e-9, Iz=4e-9, J=3e-9, orientation=(1.0, 1.0, 0.3),
                     shear_area_y=1.2e-4, shear_area_z=1.1e-4),
        BeamProperty(**base, A=1e-4, Iy=1e-9, Iz=2e-9, J=1e-9, orientation=(0.0, 0.0, 1.0),
                     offset=(0.0, 0.01, 0.02)),
    ]
    for i, (conn, p) in enumerate(zip(members, secs)):
        p = BeamProperty(**{**p.__dict__, "orientation": tuple(rotation @ p.orientation),
                            "offset": tuple(rotation @ p.offset)})
        model.add(f"m{i}", "beam2", conn, p)
    inertia = rotation @ np.diag([1e-5, 2e-5, 3e-5]) @ rotation.T  # a global-axes tensor turns with the frame
    model.add("tip", "mass", [[model.n_nodes - 1]], MassProperty(0.05, tuple(map(tuple, inertia))))
    lengths = np.linalg.norm(np.diff(corners, axis=0), axis=1)
    total = sum(p.rho * p.A * l for p, l in zip(secs, lengths)) + 0.05
    return model, total


def _rotation(seed=3):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_free_frame_rigid_modes_invariance_and_mass():
    model, total = _frame()
    modes = solve_modes(model, n_modes=10)
    assert modes.n_rigid == 6
    assert modes.frequencies[0] > 1.0
    rot, total_r = _frame(_rotation())
    modes_r = solve_modes(rot, n_modes=10)
    assert modes_r.n_rigid == 6
    assert np.max(np.abs(modes_r.frequencies / modes.frequencies - 1)) < 1e-6
    for m in (model, rot):
        _, M = assemble(m)
        for d in range(3):
            r = np.zeros(m.n_dof)
            r[d::6] = 1.0
            assert r @ (M @ r) == pytest.approx(total, rel=1e-9)


def test_rigid_motion_is_strain_free():
    """K annihilates the six rigid-body motions of one element in any direction, with offset and shear."""
    rng = np.random.default_rng(0)
    xyz = rng.normal(size=(5, 2, 3))
    p = BeamProperty(E=2e11, nu=0.3, rho=7800, A=1e-4, Iy=2e-9, Iz=1e-9, J=1.5e-9, orientation=(0.3, -0.2, 1.0),
                     offset=(0.01, -0.02, 0.03), shear_area_y=8e-5, shear_area_z=8e-5)
    K, M = matrices(xyz, p)
    for c in range(5):
        for j in range(6):
            u = np.zeros((2, 6))
            a = np.zeros(6)
            a[j] = 1.0
            for n in range(2):
                u[n, :3] = a[:3] + np.cross(a[3:], xyz[c, n])
                u[n, 3:] = a[3:]
            assert np.abs(K[c] @ u.ravel()).max() < 1e-6 * np.abs(K[c]).max()
        assert np.allclose(K[c], K[c].T) and np.allclose(M[c], M[c].T)
        assert np.linalg.eigvalsh(M[c]).min() > 0


def test_orientation_parallel_to_axis_is_an_error():
    p = BeamProperty(E=2e11, nu=0.3, rho=7800, A=1e-4, Iy=1e-9, Iz=1e-9, J=1e-9, orientation=(2.0, 0.0, 0.0))
    with pytest.raises(ModelError, match="orientation"):
        matrices(np.array([[[0.0, 0, 0], [1.0, 0, 0]]]), p)


def _ss_planar(L, h, n_el, shear, rotary=True):
    """Simply supported rectangular beam (width b = h) bending in the x-y plane only."""
    b, E, nu, rho = h, 210e9, 0.3, 7850.0
    A, I = b * h, b * h**3 / 12
    p = BeamProperty(E=E, nu=nu, rho=rho, A=A, Iy=h * b**3 / 12, Iz=I, J=0.141 * b**4, orientation=(0.0, 1.0, 0.0),
                     shear_area_y=5 / 6 * A if shear else None, shear_area_z=5 / 6 * A if shear else None,
                     rotary_inertia=rotary)
    model = _line_model(L, n_el, [("beam", np.arange(n_el), p)])
    model.fix(np.arange(n_el + 1), ["uz", "rx", "ry"])
    model.fix([0, n_el], ["uy"])
    model.fix([0], ["ux"])
    return model, p


def _timoshenko_ss(L, p, n):
    """Lower root of the Timoshenko frequency equation of a simply supported beam, mode n [Hz]."""
    k = n * np.pi / L
    EI, rA, rI, kGA = p.E * p.Iz, p.rho * p.A, p.rho * p.Iz, p.G * p.shear_area_y
    a, b, c = rA * rI / kGA, rA + rI * k**2 + rA * EI * k**2 / kGA, EI * k**4
    w2 = (b - np.sqrt(b * b - 4 * a * c)) / (2 * a)
    return np.sqrt(w2) / (2 * np.pi)


def _in_plane_bending(model, modes):
    """Frequencies of the modes whose motion is mostly transverse (uy), leaving out axial modes."""
    uy = np.abs(modes.shapes[1::6]).max(axis=0)
    ux = np.abs(modes.shapes[0::6]).max(axis=0)
    return modes.frequencies[uy > ux]


def test_timoshenko_thick_beam_matches_analytical():
    L, h = 0.5, 0.1  # L/h = 5
    model, p = _ss_planar(L, h, 40, shear=True)
    f = _in_plane_bending(model, solve_modes(model, n_modes=6))[:3]
    exact = np.array([_timoshenko_ss(L, p, n) for n in (1, 2, 3)])
    assert np.max(np.abs(f / exact - 1)) < 0.01
    eb, _ = _ss_planar(L, h, 40, shear=False, rotary=False)
    f_eb = solve_modes(eb, n_modes=1).frequencies[0]
    f_eb_exact = np.pi / (2 * L**2) * np.sqrt(p.E * p.Iz / (p.rho * p.A))
    assert f_eb == pytest.approx(f_eb_exact, rel=1e-4)
    assert f[0] < 0.97 * f_eb  # shear and rotary inertia lower a thick beam's first frequency by ~4 %


def test_timoshenko_converges_to_euler_bernoulli_when_slender():
    diffs = []
    for slender in (10, 100, 1000):
        L = 1.0
        tim, _ = _ss_planar(L, L / slender, 20, shear=True)
        eb, _ = _ss_planar(L, L / slender, 20, shear=False)
        ft = solve_modes(tim, n_modes=1).frequencies[0]
        fe = solve_modes(eb, n_modes=1).frequencies[0]
        assert ft < fe
        diffs.append(1 - ft / fe)
    # the shear correction is of order (h/L)^2: a hundredfold smaller per tenfold slenderness
    assert 90 < diffs[0] / diffs[1] < 110 and 90 < diffs[1] / diffs[2] < 110
    assert diffs[2] < 2e-6


def _end_rotation(p, L, hold_axial):
    model = _line_model(L, 4, [("b", np.arange(4), p)])
    model.fix(0)
    if hold_axial:
        model.fix(np.arange(5), ["ux"])
    K, _ = assemble(model)
    free = np.setdiff1d(np.arange(model.n_dof), list(model.fixed))
    rhs = np.zeros(model.n_dof)
    rhs[dof_index(4, "ry")] = 1.0
    u = np.zeros(model.n_dof)
    u[free] = np.linalg.solve(K[free][:, free].toarray(), rhs[free])
    return u[dof_index(4, "ry")][0]


def test_offset_gives_parallel_axis_stiffness():
    """A cantilever whose axis sits d above its nodes, under an end moment: when the nodes cannot
    stretch (as a plate holds a rib's foot), the axis strains by d * curvature and the bending
    stiffness becomes E (Iy + A d^2); when they can, the offset makes no difference."""
    L, d = 1.0, 0.02
    p = BeamProperty(E=70e9, nu=0.3, rho=2700, A=1e-4, Iy=1e-9, Iz=2e-9, J=1e-9, orientation=(0.0, 1.0, 0.0),
                     offset=(0.0, 0.0, d))
    assert _end_rotation(p, L, hold_axial=True) == pytest.approx(L / (p.E * (p.Iy + p.A * d**2)), rel=1e-9)
    assert _end_rotation(p, L, hold_axial=False) == pytest.approx(L / (p.E * p.Iy), rel=1e-9)


def test_offset_moves_the_centre_of_mass():
    """The mass matrix of an offset beam places its centre of mass at the nodes' midpoint + offset
    (read from the coupling of rigid translations and rotations)."""
    xyz = np.array([[[0.1, 0.2, -0.3], [0.5, -0.1, 0.2]]])
    e = np.array([0.01, -0.03, 0.02])
    p = BeamProperty(E=2e11, nu=0.3, rho=7800, A=1e-4, Iy=2e-9, Iz=1e-9, J=1.5e-9, orientation=(0.0, 0.0, 1.0),
                     offset=tuple(e))
    _, M = matrices(xyz, p)

    def rigid(a):
        return np.concatenate([np.concatenate([a[:3] + np.cross(a[3:], x), a[3:]]) for x in xyz[0]])

    I6 = np.eye(6)
    m = rigid(I6[0]) @ M[0] @ rigid(I6[0])
    assert m == pytest.approx(p.rho * p.A * np.linalg.norm(xyz[0, 1] - xyz[0, 0]), rel=1e-12)
    # rigid translation e_i against rotation e_j: m e_i . (e_j x c), i.e. the matrix -m skew(c)
    C = np.array([[rigid(I6[i]) @ M[0] @ rigid(I6[3 + j]) for j in range(3)] for i in range(3)])
    S = -C / m
    assert np.allclose(S, -S.T, rtol=0, atol=1e-12)
    c = np.array([S[2, 1], S[0, 2], S[1, 0]])
    assert np.allclose(c, xyz[0].mean(axis=0) + e, rtol=0, atol=1e-12)
