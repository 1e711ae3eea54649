"""CSV in and out, the thesis' noise models (eq. 5.72-5.74), and a simulated test read back and paired."""

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn.correlation import pair_modes
from pcbdyn.fe import BeamProperty, Model
from pcbdyn.fe.frf import frf_modal
from pcbdyn.fe.mesh import dof_index
from pcbdyn.fe.modal import solve_modes
from pcbdyn.testdata import (
    Dofs,
    MeasuredModes,
    Noise,
    Points,
    TestDataError,
    noisy_frequencies,
    noisy_frfs,
    noisy_shapes,
    read_modes_csv,
    read_points_csv,
    read_uff,
    write_modes_csv,
    write_points_csv,
    write_uff,
)
from pcbdyn.testdata.simulate import simulate_test


def test_modes_csv_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(0)
    pts = Points([3, 1, 2], rng.uniform(0, 0.1, (3, 3)))
    dofs = Dofs([1, 2, 3, 3], [[0, 0, 1], [0, 0, -1], [0, 0, 1], [0.6, 0.8, 0]])
    modes = MeasuredModes(pts, dofs, [101.5, 233.25], rng.standard_normal((4, 2)), [0.01, 0.02], [1.0, 0.97])
    write_modes_csv(tmp_path / "f.csv", tmp_path / "s.csv", modes)
    back = read_modes_csv(tmp_path / "f.csv", tmp_path / "s.csv")
    assert np.array_equal(back.frequencies, modes.frequencies)
    assert np.array_equal(back.shapes, modes.shapes)
    assert np.array_equal(back.damping, modes.damping) and np.array_equal(back.mpc, modes.mpc)
    assert np.allclose(back.dofs.directions, modes.dofs.directions, atol=1e-15)
    assert np.array_equal(back.dof_xyz(), modes.dof_xyz())


def test_points_csv_converts_units_and_requires_them(tmp_path):
    (tmp_path / "p.csv").write_text("point,x [mm],y [mm],dir\n1,10,20,z\n1,10,20,+x\n2,162,178,-z\n")
    pts, dofs = read_points_csv(tmp_path / "p.csv")
    assert pts.ids.tolist() == [1, 2]
    assert np.allclose(pts.xyz, [[0.010, 0.020, 0.0], [0.162, 0.178, 0.0]])
    assert dofs.codes().tolist() == [3, 1, -3]
    write_points_csv(tmp_path / "q.csv", pts, dofs)
    pts2, dofs2 = read_points_csv(tmp_path / "q.csv")
    assert np.array_equal(pts2.xyz, pts.xyz) and dofs2.codes().tolist() == [3, 1, -3]
    (tmp_path / "bad.csv").write_text("point,x,y\n1,10,20\n")
    with pytest.raises(TestDataError, match=r"bad\.csv: column 'x' has no unit"):
        read_points_csv(tmp_path / "bad.csv")


def test_noise_is_uniform_multiplicative_within_the_level():
    rng = np.random.default_rng(1)
    f = np.full(20000, 100.0)
    fn = noisy_frequencies(f, 2.0, rng)
    r = fn / f - 1
    assert np.abs(r).max() <= 0.02 and np.abs(r).max() > 0.0199
    assert abs(r.mean()) < 5e-4 and r.std() == pytest.approx(0.02 / np.sqrt(3), rel=0.03)  # U(-p, p)
    phi = rng.standard_normal((50, 4))
    assert np.all(np.abs(noisy_shapes(phi, 5.0, rng) / phi - 1) <= 0.05)
    H = rng.standard_normal((30, 2, 1)) + 1j * rng.standard_normal((30, 2, 1))
    ratio = noisy_frfs(H, 3.0, rng) / H
    assert np.allclose(ratio.imag, 0, atol=1e-15) and np.all(np.abs(ratio.real - 1) <= 0.03)
    assert np.array_equal(noisy_shapes(phi, 5.0, 42), noisy_shapes(phi, 5.0, 42))
    assert Noise.parse("f=0.5,shape=2,frf=1") == Noise(0.5, 2.0, 1.0) and Noise.parse("1") == Noise(1, 1, 1)
    with pytest.raises(ValueError, match="not understood"):
        Noise.parse("lots")


def beam_model():
    x = np.linspace(0, 0.3, 13)
    m = Model(np.column_stack([x, 0 * x, 0 * x]))
    prop = BeamProperty(E=70e9, nu=0.33, rho=2700.0, A=8e-5, Iy=2.7e-9, Iz=1.1e-10, J=4e-10, orientation=(0, 0, 1))
    m.add("b", "beam2", np.column_stack([np.arange(12), np.arange(1, 13)]), prop)
    m.fix(0)
    return m


def test_simulated_test_matches_the_model_and_pairs_back_after_a_uff_round_trip(tmp_path):
    model = beam_model()
    modes = solve_modes(model, n_modes=6)
    nodes = np.arange(2, 13)
    pts = Points(nodes, model.nodes[nodes])
    dofs = Dofs.from_codes(nodes, 3)
    rows = dof_index(nodes, "uz").ravel()
    read = sp.csr_matrix((np.ones(rows.size), (np.arange(rows.size), rows)), shape=(rows.size, model.n_dof))
    ref = Dofs.from_codes([12], 3)
    read_ref = read[-1:]
    f_axis = np.arange(1.0, 1500.0, 1.0)
    exact = simulate_test(modes, pts, dofs, read, reference=ref, read_reference=read_ref, f_axis=f_axis, zeta=0.02)
    H = frf_modal(modes, f_axis, rows, [rows[-1]], zeta=0.02, kind="accelerance")
    assert np.allclose(exact.frfs.H, H, rtol=1e-12, atol=0)
    assert np.allclose(exact.modes.shapes, modes.shapes[rows], rtol=0, atol=1e-15)
    noisy = simulate_test(modes, pts, dofs, read, reference=ref, read_reference=read_ref, f_axis=f_axis,
                          zeta=0.02, noise=Noise(1.0, 5.0, 2.0), seed=3)
    rel = noisy.modes.frequencies / modes.frequencies - 1
    assert np.abs(rel).max() <= 0.01 and np.abs(rel).max() > 0
    write_uff(tmp_path / "sim.uff", noisy)
    back = read_uff(tmp_path / "sim.uff")
    moving = np.abs(back.modes.shapes).max(0) > 0.05 * np.abs(back.modes.shapes).max()
    p = pair_modes(back.modes.shapes[:, moving], modes.shapes[rows][:, moving], back.modes.frequencies[moving],
                   modes.frequencies[moving])
    assert [q.test for q in p.pairs] == [q.model for q in p.pairs] == list(range(moving.sum()))
    assert np.allclose(back.frfs.H, noisy.frfs.H, rtol=1e-9)


def test_a_mode_invisible_at_the_test_dofs_is_simulated_not_refused():
    """A simulated test may read a mode as zero at every test DOF (a flat board's in-plane mode at
    out-of-plane DOFs): MeasuredModes keeps it, while a file's record may not hold one (test_uff)."""
    ids = np.arange(1, 4)
    points = Points(ids, np.column_stack([np.arange(3.0), np.zeros(3), np.zeros(3)]))
    dofs = Dofs(ids, np.tile([0.0, 0.0, 1.0], (3, 1)))
    m = MeasuredModes(points, dofs, [100.0, 5000.0], np.array([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]), [0.01, 0.01])
    assert not m.shapes[:, 1].any()
