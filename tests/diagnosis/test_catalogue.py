"""The catalogue's effects: exact sensitivity columns, and physically right changes when added."""

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.diagnosis import region_stiffness
from pcbdyn.diagnosis.catalogue import jointly
from pcbdyn.fe.modal import solve_modes

from diagnosis_plates import A, B, N_MODES, cantilever, frequencies, node_at, rotary_inertia, total_mass


@pytest.fixture(scope="module")
def plate():
    m = cantilever()
    layout = dg.from_model(m, suspects={"points.exc": node_at(m, 0.07, 0.06)})
    cands = dg.generate(layout, segments=3, patch=0.02, path_spacing=0.02)
    modes = solve_modes(m, n_modes=N_MODES)
    return m, layout, cands, modes, dg.frequency_columns(m, modes, cands)


@pytest.mark.parametrize("kind", list(dg.KINDS))
def test_frequency_column_equals_finite_difference_of_resolves(plate, kind):
    """df_i/dp from phi_i^T (dK - lambda_i dM) phi_i (thesis eq. 3.11 with k = i) against re-solved models
    carrying the effect at h and 2h (Richardson: error O(h^2)); the candidate tested is the one
    of its kind with the largest column."""
    m, _, cands, modes, cols = plate
    idx = [i for i, c in enumerate(cands) if c.kind == kind]
    assert idx, f"no {kind} candidate generated"
    i = idx[int(np.argmax(np.linalg.norm(cols[:, idx], axis=0)))]
    h = 1e-6 * dg.kind(kind).scale
    f0 = modes.frequencies
    d1 = frequencies(dg.add_effect(m, cands[i], h)) - f0
    d2 = frequencies(dg.add_effect(m, cands[i], 2 * h)) - f0
    fd = (4 * d1 - d2) / (2 * h)
    assert np.max(np.abs(fd - cols[:, i])) < 1e-4 * np.max(np.abs(cols[:, i]))


@pytest.mark.parametrize("kind", list(dg.KINDS))
def test_derivative_matrices_are_the_added_effect(plate, kind):
    """K(p) - K(0) = p dK/dp and M(p) - M(0) = p dM/dp exactly (the effects are linear in p)."""
    from pcbdyn.fe.assembly import assemble

    m, _, cands, _, _ = plate
    c = next(c for c in cands if c.kind == kind)
    p = 0.7 * dg.kind(kind).scale
    K0, M0 = assemble(m)
    K1, M1 = assemble(dg.add_effect(m, c, p))
    dK, dM = dg.derivatives(m, c)
    assert abs(K1 - K0 - p * dK).max() <= 1e-12 * abs(K0).max()
    assert abs(M1 - M0 - p * dM).max() <= 1e-12 * abs(M0).max()
    assert abs(dK).max() + abs(dM).max() > 0


def test_point_mass_adds_exactly_its_mass_and_lowers_every_frequency(plate):
    m, _, cands, modes, _ = plate
    c = next(c for c in cands if c.kind == "point_mass" and c.prime)
    heavy = dg.add_effect(m, c, 0.013)
    assert total_mass(heavy) - total_mass(m) == pytest.approx(0.013, rel=1e-10)
    f = frequencies(heavy)
    assert np.all(f < modes.frequencies)
    cj = next(c for c in cands if c.kind == "point_inertia")
    J = dg.add_effect(m, cj, 2e-6)
    at = np.r_[cj.at, 0.0]
    for axis, inertia in ((0, 2e-6), (1, 2e-6), (2, 0.0)):  # about in-plane axes through the point
        assert rotary_inertia(J, axis, at) - rotary_inertia(m, axis, at) == pytest.approx(inertia, rel=1e-8, abs=1e-14)
    assert total_mass(J) == pytest.approx(total_mass(m), rel=1e-14)


def test_ground_spring_at_the_antinode_raises_that_mode_and_lowers_none(plate):
    m, _, cands, modes, _ = plate
    phi_z = modes.shapes[2::6, 0]
    node = int(np.argmax(np.abs(phi_z)))
    c = next(c for c in cands if c.kind == "ground_spring" and c.nodes[0] == node)
    f = frequencies(dg.add_effect(m, c, 1e4))
    assert f[0] > 1.2 * modes.frequencies[0]
    assert np.all(f >= modes.frequencies * (1 - 1e-12))


def test_edge_stiffness_on_the_free_edge_tends_to_holding_its_rotation(plate):
    """kr about the free edge x = a raises the modes; kr -> inf gives the plate whose rotation
    about y is held along that edge. Candidates on the clamped edge x = 0 cannot act: dropped."""
    m, layout, cands, modes, _ = plate
    edge = [c for c in cands if c.kind == "edge_stiffness" and np.allclose(c.geometry["segment"][:, 0], A)]
    assert len(edge) == 6  # three pieces and their runs: 0, 1, 2, 0-1, 1-2, 0-2 (the whole edge)
    assert not [c for c in cands if c.kind == "edge_stiffness" and np.allclose(c.geometry["segment"][:, 0], 0.0)]
    whole = max(edge, key=lambda c: c.data["length"])
    assert whole.data["length"] == pytest.approx(sum(c.data["length"] for c in edge if "-" not in c.name))
    stiff = dg.add_effect(m, whole, 1e9)
    held = m.copy()
    held.fix(whole.nodes, ("ry",))
    f_stiff, f_held = frequencies(stiff), frequencies(held)
    assert np.all(f_stiff > modes.frequencies)
    assert np.max(np.abs(f_stiff / f_held - 1)) < 1e-3
    assert f_held[0] > 1.05 * modes.frequencies[0]


def test_region_stiffness_over_the_whole_plate_scales_frequencies_by_sqrt(plate):
    """Stiffness times 1 + s with the mass unchanged: every frequency times sqrt(1 + s)."""
    m, layout, _, modes, _ = plate
    whole = region_stiffness._candidate(layout, "all", [[-1, -1], [1, -1], [1, 1], [-1, 1]])
    f = frequencies(dg.add_effect(m, whole, 0.44))
    assert f == pytest.approx(1.2 * modes.frequencies, rel=1e-9)
    assert total_mass(dg.add_effect(m, whole, 0.44)) == pytest.approx(total_mass(m), rel=1e-14)
    with pytest.raises(ValueError, match="must leave the stiffness > 0"):
        dg.add_effect(m, whole, -1.0)


def test_stiffener_along_the_span_adds_its_mass_and_stiffens_the_first_bending_mode(plate):
    m, _, cands, modes, _ = plate
    c = next(c for c in cands if c.kind == "stiffener" and np.ptp(c.geometry["path"][:, 1]) < 1e-12
             and abs(c.at[1] - B / 2) < 0.011)
    assert np.allclose(c.geometry["path"][[0, -1], 0], [0.0, A])
    EI = 1.0
    ribbed = dg.add_effect(m, c, EI)
    sec = dg.kind("stiffener").section
    mu = sec.rho * 12.0 * EI / (sec.E * sec.h**2)  # rho b h with E b h^3 / 12 = EI
    assert total_mass(ribbed) - total_mass(m) == pytest.approx(mu * A, rel=1e-10)
    assert frequencies(ribbed)[0] > 1.1 * modes.frequencies[0]


def test_line_mass_adds_exactly_its_mass_along_the_segment(plate):
    m, _, cands, modes, _ = plate
    c = next(c for c in cands if c.kind == "line_mass" and np.allclose(c.geometry["segment"][:, 0], A))
    heavy = dg.add_effect(m, c, 0.02)
    assert total_mass(heavy) - total_mass(m) == pytest.approx(0.02, rel=1e-10)
    assert total_mass(heavy, dof=0) - total_mass(m, dof=0) == pytest.approx(0.02, rel=1e-10)
    assert np.all(frequencies(heavy) < modes.frequencies)


def test_unknown_kind_is_named():
    with pytest.raises(dg.CatalogueError, match="unknown effect kind 'pointmass'.*point_mass"):
        dg.kind("pointmass")


def test_overlapping_region_effects_add_up(plate):
    """A patch inside a stiffened whole plate: its cells get 1 + s_all + s_patch, the others
    1 + s_all (K is linear in each), so the two effects together equal the sum of their dK."""
    from pcbdyn.fe.assembly import assemble

    m, layout, cands, _, _ = plate
    whole = region_stiffness._candidate(layout, "all", [[-1, -1], [1, -1], [1, 1], [-1, 1]])
    patch = next(c for c in cands if c.kind == "region_stiffness")
    both = dg.add_effect(dg.add_effect(m, whole, 0.3), patch, -0.5)
    K0, _ = assemble(m)
    K2, _ = assemble(both)
    expected = K0 + 0.3 * dg.derivatives(m, whole)[0] - 0.5 * dg.derivatives(m, patch)[0]
    assert abs(K2 - expected).max() <= 1e-12 * abs(K0).max()
    with pytest.raises(ValueError, match="must leave the stiffness > 0"):
        dg.add_effect(both, patch, -0.9)


def test_overlapping_softenings_below_zero_stiffness_are_refused_on_any_mesh(plate):
    """Two regions over a 8 mm strip that holds no cell centroid of this 10 mm mesh (they share no
    cell here, but do on a 5 mm mesh): their changes add where they overlap, so -0.5 and -0.5 would
    leave no stiffness there and are refused together, though each is allowed alone; regions that
    only touch along an edge are independent."""
    m, layout, _, _, _ = plate
    a = region_stiffness._candidate(layout, "a", [[0, 0], [0.034, 0], [0.034, B], [0, B]])
    b = region_stiffness._candidate(layout, "b", [[0.026, 0], [0.06, 0], [0.06, B], [0.026, B]])
    c = region_stiffness._candidate(layout, "c", [[0.06, 0], [A, 0], [A, B], [0.06, B]])
    assert not _cells(a) & _cells(b)
    fine = cantilever(20, 16)
    fine_layout = dg.from_model(fine)
    a2, b2 = (region_stiffness._candidate(fine_layout, k.name, k.geometry["polygon"]) for k in (a, b))
    assert _cells(a2) & _cells(b2)
    ok = jointly([a, b, c])
    assert ok([-0.4, -0.4, -0.9]) and not ok([-0.5, -0.5, 0.0]) and ok([-0.5, 0.6, 0.0])
    with pytest.raises(ValueError, match="must leave the stiffness > 0"):
        dg.add_effect(dg.add_effect(fine, a2, -0.5), b2, -0.5)


def _cells(region) -> set:
    return {tuple(row) for conn in region.data["cells"].values() for row in conn}


def test_region_effect_follows_the_properties_of_the_model_it_is_applied_to(plate):
    """Candidates made on one model act on the present properties of another with the same mesh:
    a patch stiffened by s on a plate of modulus 2E equals the 2E plate plus s times its dK."""
    from pcbdyn.fe.assembly import assemble

    m, _, cands, _, _ = plate
    patch = next(c for c in cands if c.kind == "region_stiffness")
    stiffer = m.with_property("plate", E=2 * m.sets["plate"].prop.E)
    K0, _ = assemble(stiffer)
    K1, _ = assemble(dg.add_effect(stiffer, patch, 0.25))
    dK_m, dK_stiffer = dg.derivatives(m, patch)[0], dg.derivatives(stiffer, patch)[0]
    assert abs(K1 - K0 - 0.25 * dK_stiffer).max() <= 1e-12 * abs(K0).max()
    assert abs(dK_stiffer - 2 * dK_m).max() <= 1e-12 * abs(dK_stiffer).max()


def test_unknown_generation_option_is_named(plate):
    _, layout, _, _, _ = plate
    with pytest.raises(dg.CatalogueError, match="unknown option.*spacng.*spacing"):
        dg.generate(layout, kinds=["point_mass"], spacng=0.01)


@pytest.mark.parametrize("past", [2e-5, 3e-4, 3e-3])
def test_a_rib_reaching_past_the_edge_stops_at_it(plate, past):
    """A rib whose fitted end lies ``past`` [m] beyond the plate's edge x = A is the rib up to the edge:
    every piece as long where the cells hold it as drawn, none of no length (a piece of no length is a
    beam of unbounded stiffness: report case s1009 went indefinite that way), the rib's length the
    part on the plate, and the plate with it positive definite."""
    from pcbdyn.fe.assembly import assemble
    from pcbdyn.fe.modal import reduced_system
    from pcbdyn.fe.linsolve import lower_csc, cholmod_factor

    m, layout, *_ = plate
    rib = dg.kind("stiffener")
    c = rib.candidate(layout, "past", np.array([0.03, 0.031]), np.array([A + past, 0.037]))
    W, conn = c.data["weights"], c.data["conn"]
    located = np.einsum("nab,nbk->nak", W, m.nodes[conn][:, :, :2])
    lengths = np.linalg.norm(located[:, 1] - located[:, 0], axis=1)
    assert lengths.min() > 1e-3 * lengths.max()
    on_plate = (A - 0.03) * np.hypot(1.0, 0.006 / (A + past - 0.03))
    assert c.data["length"] == pytest.approx(on_plate, rel=1e-9)
    assert lengths.sum() == pytest.approx(on_plate, rel=1e-9)
    K, M = assemble(dg.add_effect(m, c, 50.0))
    _, Kr, _ = reduced_system(m, K, M)
    cholmod_factor(lower_csc(Kr))  # raises if not positive definite


def test_stiffener_across_an_unstructured_mesh_converges():
    """A rib across the six-part card's unstructured mesh at y = 112 mm (no node row there): what it
    does to the first six frequencies at the card's 6.75 mm mesh is within 0.5 % of what it does
    at a mesh four times finer (the rib is embedded; its bending follows the shell's Mindlin
    kinematics, so a coarse mesh does not stiffen it)."""
    from pathlib import Path

    from pcbdyn.board import build_model, load_board

    board = load_board(Path(__file__).resolve().parents[2] / "examples" / "six_part_card" / "board.toml")
    ratio = []
    for h in (6.75e-3, 1.6875e-3):
        bm = build_model(board, None, h, shared_mesh=True)
        rib = dg.kind("stiffener").candidate(dg.from_structure(bm), "y=112mm", np.array([0.0, 0.112]),
                                              np.array([0.162, 0.112]))
        plain = solve_modes(bm.model, n_modes=6).frequencies
        ratio.append(solve_modes(dg.add_effect(bm.model, rib, 1.0), n_modes=6).frequencies / plain)
    assert ratio[1][0] > 1.03  # the rib matters: it stiffens the first mode by 5 %
    assert np.max(np.abs(ratio[0] / ratio[1] - 1.0)) < 0.005


def _to_place(layout, cands, cols, kind):
    """The candidate of ``kind`` with the largest column; a region over four coarse cells (a
    polygon the coarse mesh resolves, so both meshes cover the same area); a point inertia as half
    of a body of 10 mm (alone its disc of 5 mm is not resolved by this 10 mm mesh: its change is
    11 % off the finer mesh's; it converges on finer ones, test_discretisation)."""
    if kind == "region_stiffness":
        return dg.kind(kind).candidate(layout, "square", [[0.02, 0.02], [0.06, 0.02], [0.06, 0.06], [0.02, 0.06]])
    if kind == "point_inertia":
        from pcbdyn.diagnosis.bodies import _body

        home = next(c for c in cands if c.kind == "point_mass" and c.prime)
        return _body(home, (*home.at, 0.0), 0.01)[1]
    idx = [i for i, c in enumerate(cands) if c.kind == kind]
    return cands[idx[int(np.argmax(np.linalg.norm(cols[:, idx], axis=0)))]]


@pytest.mark.parametrize("kind", list(dg.KINDS))
def test_placed_on_a_finer_mesh_the_effect_does_what_it_did(plate, kind):
    """A candidate placed on its own layout is itself; placed on the plate meshed twice as finely
    (as a test bench puts a hidden effect on its finer truth mesh) it changes the first
    frequencies as it did on its own mesh, to within that mesh's error on the change."""
    m, layout, cands, modes, cols = plate
    c = _to_place(layout, cands, cols, kind)
    same = dg.place(layout, c)
    assert same.name == c.name and np.array_equal(same.nodes, c.nodes)
    fine = cantilever(20, 16)
    p = dg.place(dg.from_model(fine), c)
    value = 0.5 * dg.kind(kind).scale
    change = [frequencies(dg.add_effect(model, cand, value)) / frequencies(model) - 1.0
              for model, cand in ((m, c), (fine, p))]
    assert np.max(np.abs(change[1])) > 0.01  # the effect matters
    assert np.max(np.abs(change[1] - change[0])) < 0.1 * np.max(np.abs(change[1]))


def test_a_mass_placed_on_another_mesh_sits_at_its_point():
    """A point mass moved to a mesh with no node at its point keeps its mass and its place: the
    placed dM/dm weighs 1 under a rigid heave and its first moments put it at the point."""
    coarse, fine = cantilever(), cantilever(17, 13)  # fine has no node at the coarse nodes inside
    layout = dg.from_model(coarse)
    c = next(c for c in dg.generate(layout, kinds=["point_mass"])
             if np.min(np.hypot(*(fine.nodes[:, :2] - c.at).T)) > 1e-3)
    _, dM = dg.derivatives(fine, dg.place(dg.from_model(fine), c))
    heave = np.zeros(fine.n_dof)
    heave[2::6] = 1.0
    tilt_x, tilt_y = heave.copy(), heave.copy()
    tilt_x[2::6], tilt_y[2::6] = fine.nodes[:, 0], fine.nodes[:, 1]
    assert heave @ dM @ heave == pytest.approx(1.0, rel=1e-12)
    assert [heave @ dM @ tilt_x, heave @ dM @ tilt_y] == pytest.approx(c.at, abs=1e-12)


def test_block_cache_keeps_a_kinds_group_through_a_screen_of_single_candidates_and_travels_empty(plate):
    """Every stiffener's blocks (the search's columns, made once per search) are still kept after more
    single-candidate asks than the cache holds (a screen's derivatives); a cache pickled to a worker
    arrives empty and makes the same blocks again."""
    import pickle

    from pcbdyn.diagnosis.catalogue import BlockCache

    m, _, cands, _, _ = plate
    cache = BlockCache(size=4)
    ribs = [c for c in cands if c.kind == "stiffener"]
    masses = [c for c in cands if c.kind == "point_mass"][:10]
    group = cache(m, "stiffener", ribs)
    for c in masses:
        cache(m, "point_mass", [c])
    assert cache(m, "stiffener", ribs) is group
    blob = pickle.dumps(cache)
    assert len(blob) < 1000 < sum(b.Ke.nbytes for b in group)
    sent = pickle.loads(blob)
    again = sent(m, "stiffener", ribs)
    assert again is not group and all(np.array_equal(a.Ke, b.Ke) for a, b in zip(again, group))
