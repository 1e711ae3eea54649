"""The diagnosis residual (frequencies and MAC-paired shapes in noise units): its sensitivity columns
against finite differences of full re-solves, the shape-noise estimate against the noise put in, and
configurations re-solved on a spare process against the same solves in this process."""

import numpy as np
import pytest
import scipy.sparse as sp

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis.budget import noise_sigmas
from pcbdyn.diagnosis.residual import ModalResidual, Observation
from pcbdyn.fe import EdgeSpringProperty, MassProperty, Model, ShellProperty
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import nodes_where, rectangle
from pcbdyn.fe.modal import solve_modes
from pcbdyn.fe.probe import model_probe
from pcbdyn.parallel import spare, spare_cores
from pcbdyn.testdata.noise import noisy_shapes

from diagnosis_plates import check_parameter_columns, measured

M_MODES = 6


@pytest.fixture(scope="module")
def plate():
    """A 160 x 120 x 2 mm plate on two guides (x = 0 and 160 mm), read along z at a 9 x 7 grid;
    E is a declared parameter (it scales K)."""
    nodes, conn = rectangle(0.16, 0.12, 16, 12)

    def build(p):
        m = Model(nodes)
        m.add("plate", "quad4", conn, ShellProperty(p[0], 0.3, 2000.0, 2e-3))
        for x in (0.0, 0.16):
            e = nodes_where(nodes, x=x)
            m.fix(e, ("ux", "uy", "uz", "rx", "rz"))
            m.add(f"guide{x}", "edge_spring", np.c_[e[:-1], e[1:]], EdgeSpringProperty(k=(0, 0, 0, 200.0, 0, 0)))
        return m

    gx, gy = np.meshgrid(np.linspace(0.01, 0.15, 9), np.linspace(0.01, 0.11, 7))
    xyz = np.c_[gx.ravel(), gy.ravel(), np.zeros(gx.size)]
    zdir = np.tile([0.0, 0.0, 1.0], (gx.size, 1))
    base = build([24e9])
    read = model_probe(base, xyz, zdir).P
    modes = solve_modes(base, n_modes=M_MODES)
    ob = Observation(None, measured(modes.frequencies * 1.01, np.asarray(read @ modes.shapes), xyz, zdir),
                     np.full(M_MODES, 1e-3), read, np.full(M_MODES, 1e-2))

    def derivatives(p, models):  # E enters the plate's stiffness linearly
        n = models[0].n_dof
        return [[(assemble(build([1.0]), sets=["plate"])[0], sp.csr_matrix((n, n)))]]

    res = ModalResidual([ob], lambda p: [build(p)], derivatives, n_params=1)
    cands = dg.generate(dg.from_model(base), kinds=["point_mass", "ground_spring", "region_stiffness"], patch=0.04)
    return res, cands, ob, read, modes


def fd_column(res, p, cands, values, k, h):
    up, dn = values.copy(), values.copy()
    up[k] += h
    dn[k] -= h
    r_up, r_dn = res.evaluate(p, cands, up).r, res.evaluate(p, cands, dn).r
    return -(r_up - r_dn) / (2 * h)  # rows are measured - predicted


@pytest.mark.parametrize("kind, xy", [("point_mass", (0.1, 0.07)), ("ground_spring", (0.05, 0.03)),
                                      ("region_stiffness", (0.1, 0.06))])
def test_effect_columns_match_resolves(plate, kind, xy):
    """Frequency rows equal central differences of full re-solves (eq. 3.6, exact); the shape rows,
    from the modal expansion of the eigenvector derivative over the computed modes, point the same
    way (cosine > 0.98) with a norm within 10 %."""
    res, cands, ob, *_ = plate
    c = min((c for c in cands if c.kind == kind), key=lambda c: np.hypot(c.at[0] - xy[0], c.at[1] - xy[1]))
    p = np.array([24e9])
    a = res.effect_columns(res.evaluate(p, [c], [0.0]), [c])[:, 0]
    h = 1e-4 * c.spec.scale
    fd = fd_column(res, p, [c], np.array([0.0]), 0, h)
    m = M_MODES
    assert np.allclose(a[:m], fd[:m], rtol=1e-4, atol=1e-6 * np.abs(fd[:m]).max())
    s, sf = a[m:], fd[m:]
    assert s @ sf / (np.linalg.norm(s) * np.linalg.norm(sf)) > 0.98
    assert np.linalg.norm(s) == pytest.approx(np.linalg.norm(sf), rel=0.1)


def test_parameter_columns_match_resolves(plate):
    """A parameter acting over the whole plate (E against the guides' springs): frequency rows exact,
    shape rows with the modes beyond the computed ones added quasi-statically within 5 %
    (cosine > 0.99)."""
    res, *_ = plate
    check_parameter_columns(res, np.array([24e9]), M_MODES)


@pytest.mark.parametrize("pct", [1.0, 2.0, 5.0])
def test_shape_noise_estimate(plate, pct):
    """Uniform multiplicative shape noise of +-pct % (eq. 5.73) is estimated, as a standard deviation
    per RMS of the shape, within 25 % of its expected pct / sqrt(3) on 63 points and 6 modes."""
    res, _, ob, read, modes = plate
    model = res.build([24e9])[0]
    wide = solve_modes(model, n_modes=read.shape[0] // 2)
    basis = np.asarray(read @ wide.shapes)
    phi = np.asarray(read @ modes.shapes)
    noisy = Observation(None, measured(ob.f, noisy_shapes(phi, pct, seed=4)), ob.sigma_f, read, None)
    _, ss = noise_sigmas(noisy, 0.2, None, basis)
    assert np.mean(ss) == pytest.approx(pct / 100 / np.sqrt(3), rel=0.25)


def test_configurations_solved_beside_give_the_same_state(plate):
    """Three configurations (the plate, with a 20 g mass, and with a mass whose inertia couples its
    bending and membrane DOFs, so that it solves as one group) re-solved with a spare process give
    the residual of the same solves in this process, bit for bit, whichever process solved which."""
    res, cands, ob, _, _ = plate
    inertias = (None, (1e-6, 1e-6, 1e-6), ((2e-6, 0.0, 1e-6), (0.0, 2e-6, 0.0), (1e-6, 0.0, 2e-6)))

    def build(p):
        out = []
        for J in inertias:
            m = res.build(p)[0]
            if J is not None:
                m.add("mass", "mass", [[40]], MassProperty(0.02, J))
            out.append(m)
        return out

    def residual():
        return ModalResidual([ob] * 3, build, res.derivatives, n_params=1)

    alone = residual()
    states = [alone.evaluate([24e9], cands[:1], [0.01]).r for _ in range(2)]
    with spare_cores(2):
        assert spare() == 1
        beside = residual()
        states += [beside.evaluate([24e9], cands[:1], [0.01]).r for _ in range(3)]  # the 2nd on measured times
    assert spare() == 0
    for r in states[1:]:
        np.testing.assert_array_equal(r, states[0])
