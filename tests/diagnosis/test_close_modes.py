"""Close modes in the diagnosis residual: a near-square plate's (1,2) and (2,1) modes, turned within their
plane by a mass too small to move a frequency beyond the noise, are compared as a plane, and the
residual's sensitivity columns still match finite differences of full re-solves."""

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn.correlation.close_modes import align_close, close_groups
from pcbdyn.correlation.mac import paired_mac
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.fe import MassProperty, Model, ShellProperty
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle, rectangle_edges
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import model_probe

from diagnosis_plates import check_parameter_columns, measured

A, B, N = 0.12, 0.1201, 4  # plate sides [m], 0.1 % apart; modes read
SIGMA_F, SIGMA_S = 2e-3, 1e-2


def test_close_groups_join_neighbours_within_three_sigmas():
    """Modes 0.3 % apart at 0.2 % noise are one group (3 sigma of the difference is 0.85 %), chains join,
    modes 1.5 % apart are not."""
    f = np.array([200.1, 100.0, 150.0, 100.3, 200.0, 200.2, 152.3])
    assert close_groups(f, 2e-3 * f) == [(1, 3), (4, 0, 5)]


def test_a_turned_pair_is_turned_back():
    """Two orthonormal model shapes, and measured ones that are the same pair turned by 40 degrees and scaled:
    aligned, each measured shape is its model shape again (up to its scale), the other modes untouched."""
    rng = np.random.default_rng(3)
    u = np.linalg.qr(rng.normal(size=(30, 3)))[0]
    c, s = np.cos(0.7), np.sin(0.7)
    x = u.copy()
    x[:, :2] = u[:, :2] @ np.array([[c, -s], [s, c]]) * [2.0, 3.0]
    out = align_close(x, u, [(0, 1)])
    np.testing.assert_allclose(paired_mac(out, u)[:2], 1.0, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(out, axis=0), np.linalg.norm(x, axis=0))
    np.testing.assert_array_equal(out[:, 2], x[:, 2])


@pytest.fixture(scope="module")
def square():
    """A simply supported 120 x 120.1 x 1.6 mm plate read along z at 9 x 9 points, whose corner patch
    (x, y < 50 mm) has the declared modulus; its 'test' is the same plate with 0.02 g at (31, 22) mm:
    no frequency moves by half a noise sigma, the (1,2)/(2,1) pair turns."""
    nodes, conn = rectangle(A, B, 16, 16)
    edge = np.unique(np.concatenate(list(rectangle_edges(nodes, A, B).values())))
    mid = nodes[conn].mean(axis=1)
    patch = (mid[:, 0] < 0.05) & (mid[:, 1] < 0.05)

    def build(p, mass=0.0):
        m = Model(nodes)
        m.add("plate", "quad4", conn[~patch], ShellProperty(22e9, 0.3, 1900.0, 1.6e-3))
        m.add("patch", "quad4", conn[patch], ShellProperty(p[0], 0.3, 1900.0, 1.6e-3))
        m.fix(edge, ("ux", "uy", "uz"))
        if mass:
            k = int(np.argmin(np.hypot(nodes[:, 0] - 0.031, nodes[:, 1] - 0.022)))
            m.add("mass", "mass", [[k]], MassProperty(mass))
        return m

    gx, gy = np.meshgrid(np.linspace(0.01, A - 0.01, 9), np.linspace(0.01, B - 0.01, 9))
    xyz = np.c_[gx.ravel(), gy.ravel(), np.zeros(gx.size)]
    zdir = np.tile([0.0, 0.0, 1.0], (gx.size, 1))
    test = solve_modes(build([22e9], mass=2e-5), n_modes=N)
    read = model_probe(build([22e9]), xyz, zdir).P
    ob = Observation(None, measured(test.frequencies, np.asarray(read @ test.shapes), xyz, zdir),
                     np.full(N, SIGMA_F), read, np.full(N, SIGMA_S), noise_f=np.full(N, SIGMA_F))

    def derivatives(p, models):  # the patch's modulus enters its stiffness linearly
        n = models[0].n_dof
        return [[(assemble(build([1.0]), sets=["patch"])[0], sp.csr_matrix((n, n)))]]

    return ModalResidual([ob], lambda p: [build(p)], derivatives, n_params=1), ob, build


def test_the_turned_pair_is_no_misfit(square):
    """The declared plate against the test of the plate with 0.02 g: the pair is found close and compared
    as a plane (MAC > 0.999 where the modes one by one have MAC < 0.95), so chi^2 stays below its
    number of rows: a trifle the frequencies do not see is not a misfit of the shapes."""
    res, ob, build = square
    f_model = solve_modes(build([22e9]), n_modes=N).frequencies
    assert np.max(np.abs(ob.f / f_model - 1)) < SIGMA_F / 2
    st = res.evaluate(np.array([22e9]))
    cs = st.configs[0]
    assert cs.close == ((1, 2),)
    assert paired_mac(cs.u, ob.shapes)[1:3].max() < 0.95
    assert paired_mac(cs.u, cs.x)[1:3].min() > 0.999
    assert cs.r @ cs.r < ob.n_rows
    assert st.summary([ob])["configurations"][0]["close_test_modes"] == [[2, 3]]


def test_columns_match_resolves_across_a_close_pair(square):
    """The patch's modulus, 3 % off: frequency rows exact, shape rows within 5 % (cosine > 0.99) of
    central differences of the aligned residual (the turn within the pair left to the alignment)."""
    res, ob, _ = square
    p = np.array([22e9 * 1.03])
    assert res.evaluate(p).configs[0].close == ((1, 2),)
    check_parameter_columns(res, p, N)
