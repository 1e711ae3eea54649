"""Reading a shell model at arbitrary points through the element shape functions (pcbdyn.fe.probe)."""

import numpy as np
import pytest

from pcbdyn.fe import Model, ShellProperty
from pcbdyn.fe.generate import rectangle, rectangle_edges
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import ProbeError, interpolation_matrix, locate, model_probe

XI = np.array([-1.0, 1.0, 1.0, -1.0])
ETA = np.array([-1.0, -1.0, 1.0, 1.0])


def grid_mesh(nx, ny, a, b, z=None):
    x, y = np.meshgrid(np.linspace(0, a, nx + 1), np.linspace(0, b, ny + 1), indexing="ij")
    zz = np.zeros_like(x) if z is None else z(x, y)
    nodes = np.column_stack([x.ravel(), y.ravel(), zz.ravel()])
    nid = np.arange(nodes.shape[0]).reshape(nx + 1, ny + 1)
    quads = np.column_stack([nid[:-1, :-1].ravel(), nid[1:, :-1].ravel(), nid[1:, 1:].ravel(), nid[:-1, 1:].ravel()])
    return nodes, quads


def field(nodes, fx, fy, fz):
    u = np.zeros(6 * len(nodes))
    u[0::6], u[1::6], u[2::6] = fx(nodes), fy(nodes), fz(nodes)
    u[3::6] = 1e3  # rotations must not leak into the translations read
    return u


def test_bilinear_fields_are_reproduced_exactly_on_a_flat_quad_mesh_in_any_direction():
    nodes, quads = grid_mesh(7, 5, 0.21, 0.15)
    rng = np.random.default_rng(0)
    p = np.column_stack([rng.uniform(0, 0.21, 300), rng.uniform(0, 0.15, 300), np.zeros(300)])
    d = rng.standard_normal((300, 3))
    fx = lambda n: 1 + 2 * n[:, 0] - n[:, 1] + 30 * n[:, 0] * n[:, 1]
    fy = lambda n: -0.5 + 4 * n[:, 1]
    fz = lambda n: 0.3 - 7 * n[:, 0] + 2 * n[:, 1] - 50 * n[:, 0] * n[:, 1]
    probe = interpolation_matrix(nodes, [("quad4", quads)], p, d)
    exact = np.einsum("ij,ij->i", np.column_stack([fx(p), fy(p), fz(p)]), d / np.linalg.norm(d, axis=1)[:, None])
    assert np.abs(probe.P @ field(nodes, fx, fy, fz) - exact).max() < 1e-12
    assert probe.found.all() and probe.location.distance.max() < 1e-12
    assert np.allclose(probe.P.sum(axis=1), (d / np.linalg.norm(d, axis=1)[:, None]).sum(1)[:, None])


def test_linear_fields_on_triangles_and_the_cell_found():
    nodes, cells = rectangle(0.2, 0.1, 8, 4, kind="tri3")
    rng = np.random.default_rng(1)
    c = rng.integers(0, len(cells), 200)
    bary = rng.dirichlet([1, 1, 1], 200) * 0.98 + 0.02 / 3  # strictly inside
    p = np.einsum("mv,mvk->mk", bary, nodes[cells[c]])
    fz = lambda n: 0.1 + 3 * n[:, 0] - 5 * n[:, 1]
    probe = interpolation_matrix(nodes, [("tri3", cells)], p)
    assert np.abs(probe.P @ field(nodes, fz, fz, fz) - fz(p)).max() < 1e-12
    assert np.array_equal(probe.location.cell, c)


def test_points_on_a_warped_3d_mesh_of_quads_and_triangles_are_located_and_interpolated():
    nodes, quads = grid_mesh(6, 5, 0.3, 0.2, z=lambda x, y: 0.03 * np.sin(5 * x) * np.cos(4 * y))
    tris = np.vstack([quads[20:][:, [0, 1, 2]], quads[20:][:, [0, 2, 3]]])
    cells = [("quad4", quads[:20]), ("tri3", tris)]
    rng = np.random.default_rng(2)
    k = rng.integers(0, 20, 150)
    xi, eta = rng.uniform(-1, 1, (2, 150))
    N = 0.25 * (1 + xi[:, None] * XI) * (1 + eta[:, None] * ETA)
    p = np.einsum("ma,mak->mk", N, nodes[quads[k]])  # points on the (curved) bilinear patches
    u = field(nodes, lambda n: np.cos(n[:, 0]), lambda n: np.sin(n[:, 1]), lambda n: np.arange(len(n)) ** 1.3)
    probe = interpolation_matrix(nodes, cells, p)
    assert np.abs(probe.P @ u - np.einsum("ma,ma->m", N, u[2::6][quads[k]])).max() < 1e-10
    assert probe.location.distance.max() < 1e-10
    # a point lifted 0.1 mm off the surface along z is still read, and reported at that distance
    q = p[:5] + [0, 0, 1e-4]
    loc = locate(nodes, cells, q)
    assert loc.found.all() and np.all(loc.distance < 1.01e-4)


def test_points_off_the_model_are_listed_or_masked():
    nodes, quads = grid_mesh(4, 4, 0.1, 0.1)
    p = [[0.05, 0.05, 0.0], [0.2, 0.05, 0.0], [0.05, 0.05, 0.01]]
    with pytest.raises(ProbeError, match=r"2 point\(s\) are not on the model: #1 at \[0.2, 0.05, 0.0\]"):
        interpolation_matrix(nodes, [("quad4", quads)], p)
    probe = interpolation_matrix(nodes, [("quad4", quads)], p, missing="mask")
    assert probe.found.tolist() == [True, False, False]
    assert probe.P[1].nnz == 0 and probe.P[2].nnz == 0
    assert probe.location.distance[1] == pytest.approx(0.1) and probe.location.distance[2] == pytest.approx(0.01)
    # a wider tolerance accepts the point 10 mm above the plate
    assert interpolation_matrix(nodes, [("quad4", quads)], p[2:], tol=0.02).found.all()


A, B = 0.162, 0.178


def plate(n):
    """A 162 x 178 x 1.6 mm FR4-like plate, edges held in translation (simply supported), n x n quads."""
    nodes, cells = rectangle(A, B, n, n)
    model = Model(nodes)
    model.add("board", "quad4", cells, ShellProperty(E=26e9, nu=0.3, rho=2000.0, t=1.6e-3))
    edges = rectangle_edges(nodes, A, B)
    model.fix(np.unique(np.concatenate(list(edges.values()))), ["ux", "uy", "uz"])
    return model


@pytest.fixture(scope="module")
def plates():
    return {n: (m, solve_modes(m, 4)) for n, m in ((n, plate(n)) for n in (12, 24, 48, 96))}


def test_a_plate_read_between_its_nodes_matches_a_finer_mesh_with_nodes_there(plates):
    """Issue 4: reading through the shape functions is within 0.5 % of a mesh with nodes at the points
    (48 x 48 model read at the other nodes of a 96 x 96 mesh), MAC > 0.999, and converges as h^2."""
    fine, fine_modes = plates[96]
    errors = {}
    for n in (12, 24, 48):
        coarse, modes = plates[n]
        ij = fine.nodes[:, :2] / [A / n, B / n]
        between = ~np.all(np.abs(ij - np.round(ij)) < 1e-9, axis=1)  # fine nodes that are not coarse nodes
        probe = model_probe(coarse, fine.nodes[between])
        read = probe.P @ modes.shapes
        ref = fine_modes.shapes[6 * np.flatnonzero(between) + 2]
        read *= np.sign(np.sum(read * ref, axis=0))  # both sets are mass-normalised: no rescaling
        errors[n] = np.abs(read - ref).max(0) / np.abs(ref).max(0)
        cos2 = np.sum(read * ref, 0) ** 2 / (np.sum(read**2, 0) * np.sum(ref**2, 0))
        assert cos2.min() > 0.999
        if n == 48:
            assert errors[n].max() < 0.005  # every mode within 0.5 % of its peak
            near = np.argmin(((fine.nodes[between][:, None, :2] - coarse.nodes[None, :, :2]) ** 2).sum(2), axis=1)
            nearest = modes.shapes[6 * near + 2]
            nearest *= np.sign(np.sum(nearest * ref, axis=0))
            # reading the nearest node instead is several times worse
            assert np.all(np.abs(nearest - ref).max(0) / np.abs(ref).max(0) > 5 * errors[n])
    # the interpolation error falls with the square of the cell size, as bilinear interpolation should
    for coarse, finer in ((12, 24), (24, 48)):
        assert np.all((errors[coarse] / errors[finer] > 3.2) & (errors[coarse] / errors[finer] < 4.8))
