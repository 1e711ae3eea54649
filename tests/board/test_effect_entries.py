"""The board entries of the diagnosis effect kinds and the enriched board.toml (issue 7).

For every kind: a diagnosis candidate on a plate board, added with ``add_effect``, is written into
an enriched board.toml with ``write_enriched``; the built board must be the diagnosed model.
The new hard points and lines of the enriched board change gmsh's unstructured mesh, so the check
is in two parts:
- same mesh, exact: on the enriched board's own mesh, the board without the entry plus the
  diagnosis effect at the same place and value has the same first 8 frequencies (1e-6 relative,
  in practice round-off) and the same mass;
- across meshes: against the diagnosed model on the original mesh, within the discretisation
  difference of the two meshes (measured on the bare boards), plus the total mass exactly.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.board import BoardError, build_model, load_board
from pcbdyn.board.effects import ScaledShell, rib_property
from pcbdyn.board.enrich import enriched_path
from pcbdyn.diagnosis.catalogue import Candidate, chain_candidate
from pcbdyn.fe.elements import kernel
from pcbdyn.fe.modal import solve_modes

from board_helpers import write_board

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "diagnosis"))
from diagnosis_plates import rotary_inertia, total_mass  # noqa: E402
from data_files import board_text

N = 8
BASE = board_text("guided_plate.toml")

# kind -> (value [SI], point the candidate is nearest to [m])
CASES = {
    "point_mass": (0.02, (0.07, 0.06)),
    "point_inertia": (3e-6, (0.1, 0.08)),
    "ground_spring": (2e4, (0.07, 0.06)),
    "edge_stiffness": (50.0, (0.1, 0.04)),
    "line_mass": (0.01, (0.05, 0.08)),
    "stiffener": (5.0, (0.05, 0.04)),
    "region_stiffness": (0.5, (0.05, 0.05)),
    "region_mass": (0.005, (0.05, 0.05)),  # a fifth of the board: its spread differs between the two meshes
}


def write_enriched(path, effects, out_path=None, date=None):
    """The board at ``path`` with ``effects`` declared, written to ``out_path`` (default beside it)."""
    return load_board(path).write_enriched(effects, out_path or enriched_path(path), date)


def freqs(model):
    return solve_modes(model, n_modes=N).frequencies


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    path = write_board(tmp_path_factory.mktemp("base"), BASE)
    bm = build_model(load_board(path))
    layout = dg.from_structure(bm)
    cands = dg.generate(layout, segments=4, patch=0.02, path_spacing=0.02)
    return path, bm, cands, freqs(bm.model)


def pick(cands, kind, near):
    cs = [c for c in cands if c.kind == kind]
    return min(cs, key=lambda c: np.linalg.norm(np.asarray(c.at) - near))


def as_effect(c, value):
    return {"type": c.kind, "name": c.name, "value": value, "at": c.at, **c.geometry}


def same_mesh_diagnosis(bmE, kind, effect):
    """(base model on the enriched board's mesh, diagnosis candidate there) for ``effect``."""
    bd = bmE.board
    m = bmE.model
    if kind in ("point_mass", "point_inertia"):
        name = bd.masses[-1].name
        base = m.copy()
        del base.sets[f"masses.{name}"]
        return base, Candidate(kind, "c", effect["at"], np.array([bmE.point_nodes[f"masses.{name}"]]))
    if kind == "ground_spring":
        name = bd.fixtures[-1].name
        base = m.copy()
        del base.sets[f"fixtures.{name}"]
        return base, Candidate(kind, "c", effect["at"], np.array([bmE.point_nodes[f"fixtures.{name}"]]))
    if kind in ("region_stiffness", "region_mass"):
        r = bd.regions[-1]
        if kind == "region_stiffness":
            base = bmE.with_quantities({f"regions.{r.name}.stiffness_factor": 1.0}).model
        else:
            base = bmE.with_quantities({f"regions.{r.name}.mass": 0.0}).model
        layout = dg.from_model(base, thickness=bd.thickness)
        cs = [c for c in dg.generate(layout, kinds=[kind], patch=0.02)
              if np.allclose(c.geometry["polygon"], effect["polygon"], atol=1e-9)]
        assert len(cs) == 1
        return base, cs[0]
    prefix = {"edge_stiffness": lambda: f"fixtures.{bd.fixtures[-1].name}",
              "line_mass": lambda: f"line_masses.{bd.line_masses[-1].name}",
              "stiffener": lambda: f"stiffeners.{bd.stiffeners[-1].name}"}[kind]()
    base = m.copy()
    for s in [s for s in base.sets if s == prefix or s.startswith(prefix + ".")]:
        del base.sets[s]
    pts = np.asarray(effect["path" if kind == "stiffener" else "segment"])
    layout = dg.from_model(base, thickness=bd.thickness)
    if kind == "stiffener":  # a straight rib, embedded: on the board's mesh line its pieces end on the nodes
        return base, dg.kind(kind).candidate(layout, "c", pts[0], pts[-1])
    pieces = [bmE.mesh.chain_on_segment(a, b) for a, b in zip(pts[:-1], pts[1:])]
    chain = np.concatenate([pieces[0]] + [p[1:] for p in pieces[1:]])
    return base, chain_candidate(kind, layout, "c", chain)


@pytest.mark.parametrize("kind", list(CASES))
def test_enriched_board_is_the_diagnosed_model(base, tmp_path, kind):
    path, bm0, cands, f0 = base
    value, near = CASES[kind]
    cand = pick(cands, kind, near)
    diagnosed = dg.add_effect(bm0.model, cand, value)
    f_diag = freqs(diagnosed)
    effect = as_effect(cand, value)
    out = write_enriched(path, [effect], out_path=tmp_path / "board.diagnosed.toml")
    assert out.read_text().startswith(path.read_text())
    bmE = build_model(load_board(out))
    fE = freqs(bmE.model)

    # same mesh: the board entry is exactly the diagnosis effect
    baseE, candE = same_mesh_diagnosis(bmE, kind, effect)
    fE_diag = freqs(dg.add_effect(baseE, candE, value))
    assert np.max(np.abs(fE / fE_diag - 1)) < 1e-6
    assert total_mass(bmE.model) == pytest.approx(total_mass(dg.add_effect(baseE, candE, value)), rel=1e-12)
    f_baseE = freqs(baseE)
    assert np.max(np.abs(fE / f_baseE - 1)) > 1e-3  # the effect does something

    # across meshes: the diagnosed model on the original mesh, within the meshes' own difference
    # (a stiffener crossing the original mesh's cells, embedded, is up to 2.5 % stiffer than on a
    # mesh line: tests/fe/test_rib.py; a region on the original 10 mm mesh is the cells whose centroids
    # lie in the 20 mm patch, up to 30 mm across, where the enriched mesh follows the polygon: a mass of
    # a fifth of the board's spread over either differs by 1.7 % at most)
    mesh_diff = np.max(np.abs(f_baseE / f0 - 1))
    assert mesh_diff < 0.03
    slack = {"stiffener": 0.025, "region_mass": 0.01}.get(kind, 0.0)
    assert np.max(np.abs(fE / f_diag - 1)) < 2 * mesh_diff + 2e-3 + slack
    if kind in ("point_mass", "line_mass"):
        assert bmE.mass() == pytest.approx(bm0.mass() + value, rel=1e-10)
        assert bmE.mass() == pytest.approx(total_mass(diagnosed), rel=1e-10)
    else:
        assert bmE.mass() == pytest.approx(total_mass(diagnosed) if kind != "stiffener" else bm0.mass()
                                           + total_mass(diagnosed) - total_mass(bm0.model), rel=1e-10)
    if kind == "point_inertia":  # a rigid rotation about an in-plane axis through the point sees J
        at = np.r_[effect["at"], 0.0]
        for axis, J in ((0, value), (1, value), (2, 0.0)):
            assert rotary_inertia(bmE.model, axis, at) - rotary_inertia(baseE, axis, at) == pytest.approx(
                J, rel=1e-9, abs=1e-9 * value)


def test_point_mass_and_inertia_at_one_point_merge(base, tmp_path):
    path, bm0, cands, _ = base
    m = pick(cands, "point_mass", (0.07, 0.06))
    J = pick(cands, "point_inertia", (0.07, 0.06))
    assert m.nodes[0] == J.nodes[0]
    out = write_enriched(path, [as_effect(m, 0.02), as_effect(J, 3e-6)], date="2024-01-02")
    assert out == enriched_path(path) and out.name == "board.diagnosed.toml"
    text = out.read_text()
    assert "# found by pcbdyn diagnose on 2024-01-02" in text
    b = load_board(out)
    assert len(b.masses) == 1
    assert b.masses[0].mass == pytest.approx(0.02) and b.masses[0].inertia == pytest.approx(3e-6)
    assert b.masses[0].at == pytest.approx(m.at, abs=1e-12)
    both = dg.add_effect(dg.add_effect(bm0.model, m, 0.02), J, 3e-6)
    bmE = build_model(b)
    assert bmE.mass() == pytest.approx(total_mass(both), rel=1e-12)


def test_all_kinds_in_one_file_and_parameters_target_them(base, tmp_path):
    """Every kind at once; the new quantities are parameter targets whose derivatives match a
    rebuild at the changed value."""
    path, bm0, cands, _ = base
    effects = [as_effect(pick(cands, k, near), v) for k, (v, near) in CASES.items()]
    out = write_enriched(path, effects, out_path=tmp_path / "all.toml")
    b = load_board(out)
    assert [f.type for f in b.fixtures] == ["wedge_lock", "point_spring", "edge_spring"]
    assert len(b.line_masses) == len(b.stiffeners) == 1 and len(b.regions) == 2
    targets = {"k_s": (f"fixtures.{b.fixtures[1].name}.k", "N/m", 2e4),
               "kr_e": (f"fixtures.{b.fixtures[2].name}.k_rot", "N*m/rad/m", 50.0),
               "m_l": (f"line_masses.{b.line_masses[0].name}.mass", "g", 0.01),
               "EI": (f"stiffeners.{b.stiffeners[0].name}.EI", "N*m^2", 5.0),
               "f_r": (f"regions.{b.regions[0].name}.stiffness_factor", "dimensionless", 1.5),
               "m_r": (f"regions.{b.regions[1].name}.mass", "g", 0.005)}
    text = out.read_text()
    for name, (t, unit, v) in targets.items():
        assert b.quantity(t) == pytest.approx(v)
        lo, hi = (f'"{v * s:.12g} {unit}"' if unit != "dimensionless" else f"{v * s:.12g}" for s in (0.5, 2.0))
        if unit == "g":
            lo, hi = (f'"{v * s * 1e3:.12g} g"' for s in (0.5, 2.0))
        text += f'\n[[parameters]]\nname = "{name}"\ntarget = "{t}"\nbounds = [{lo}, {hi}]\n'
    p2 = tmp_path / "with_params.toml"
    p2.write_text(text)
    bm = build_model(load_board(p2))
    f1 = freqs(bm.model)
    for name, (t, _, v) in targets.items():
        par = bm.parameters[name]
        assert par.value == pytest.approx(v)
        changed = bm.with_parameters({name: 1.3 * v})
        f2 = freqs(changed.model)
        assert np.max(np.abs(f2 / f1 - 1)) > 1e-5, name
        dK, dM = par.derivatives(bm)
        assert abs(dK).max() + abs(dM).max() > 0, name
        from pcbdyn.fe.assembly import assemble

        K1, M1 = assemble(bm.model)
        K2, M2 = assemble(changed.model)
        assert abs((K2 - K1) - 0.3 * v * dK).max() <= 1e-7 * abs(K1).max(), name
        assert abs((M2 - M1) - 0.3 * v * dM).max() <= 1e-7 * abs(M1).max(), name


def test_stiffener_section_has_the_bending_stiffness_asked():
    """The rib's section (shared with the diagnosis stiffener kind): E I = EI about both axes,
    mass rho b h per length with b = 12 EI / (E h^3), axis (t + h) / 2 above the mid-surface."""
    from pcbdyn.board.entries import RibSection

    s = RibSection()
    for EI in (0.3, 7.0):
        prop = rib_property(EI, 1.6e-3)
        assert prop.E * prop.Iy == pytest.approx(EI, rel=1e-12) and prop.Iz == prop.Iy
        assert prop.rho * prop.A == pytest.approx(s.rho * 12 * EI / (s.E * s.h**2), rel=1e-12)
        assert prop.offset[2] == pytest.approx(0.5 * (1.6e-3 + s.h))


def test_edge_spring_on_a_slanted_edge_resists_rotation_about_that_edge_only(tmp_path):
    """k index 3 of the edge spring is the rotation about the segment (edge axis 1), whatever its
    direction: a rotation theta about the slanted edge stores kr L theta^2 / 2, one about the
    in-plane normal to it stores nothing."""
    text = board_text("slanted_edge_spring.toml")
    bm = build_model(load_board(write_board(tmp_path, text)))
    es = bm.model.sets["fixtures.slant"]
    K, _ = kernel("edge_spring")(bm.model.nodes[es.conn], es.prop)
    d = np.array([-20.0, 40.0]) / np.hypot(20.0, 40.0)
    L = np.hypot(0.02, 0.04)
    for axis, expect in ((np.r_[d, 0.0], 300.0 * L), (np.r_[-d[1], d[0], 0.0], 0.0)):
        u = np.zeros(12)
        u[3:6] = u[9:12] = axis
        energy = np.einsum("a,nab,b->", u, K, u)
        assert energy == pytest.approx(expect, abs=1e-9)


def test_region_shells_are_scaled_in_stiffness_not_mass(base, tmp_path):
    path, *_ = base
    text = path.read_text() + '\n[[regions]]\nname = "r"\nrect = ["20 mm", "20 mm", "60 mm", "50 mm"]\nstiffness_factor = 1.3\n'
    bm = build_model(load_board(write_board(tmp_path, text, "r.toml")))
    sets = [n for n in bm.model.sets if n.startswith("regions.r.")]
    assert sets
    for n in sets:
        p = bm.model.sets[n].prop
        assert isinstance(p, ScaledShell) and p.factor == 1.3
        c = bm.model.nodes[bm.model.sets[n].conn][:, :, :2].mean(axis=1)
        assert np.all((c > [0.02, 0.02]) & (c < [0.06, 0.05]))
    def area(conn):
        p = bm.model.nodes[conn][:, :, :2]
        q = np.roll(p, -1, axis=1)
        return 0.5 * np.sum(p[..., 0] * q[..., 1] - q[..., 0] * p[..., 1])

    # element edges follow the rectangle: its cells cover it exactly
    assert sum(area(bm.model.sets[n].conn) for n in sets) == pytest.approx(0.04 * 0.03, rel=1e-9)
    plain = build_model(load_board(write_board(tmp_path, text.replace("1.3", "1.0"), "r1.toml")))
    assert bm.mass() == pytest.approx(plain.mass(), rel=1e-13)
    assert np.all(freqs(bm.model) > freqs(plain.model))


BAD = {
    "negative spring": ('[[fixtures]]\nname = "s"\ntype = "point_spring"\nat = ["50 mm", "40 mm"]\nk = "-1e4 N/m"\n',
                        r"fixtures\[1\]\.k: must be positive"),
    "spring without unit": ('[[fixtures]]\nname = "s"\ntype = "point_spring"\nat = ["50 mm", "40 mm"]\nk = 1e4\n',
                            r"fixtures\[1\]\.k: 10000.0 has no unit"),
    "spring off the board": ('[[fixtures]]\ntype = "point_spring"\nat = ["150 mm", "40 mm"]\nk = "1e4 N/m"\n',
                             r"fixtures\[1\]\.at: .* not on the board"),
    "negative edge spring": ('[[fixtures]]\ntype = "edge_spring"\nfrom = ["100 mm", "0 mm"]\nto = ["100 mm", "40 mm"]\n'
                             'k_rot = "-5 N*m/rad/m"\n', r"fixtures\[1\]\.k_rot: must be positive"),
    "edge segment not on the outline": ('[[fixtures]]\ntype = "edge_spring"\nfrom = ["50 mm", "0 mm"]\n'
                                        'to = ["50 mm", "40 mm"]\nk_rot = "5 N*m/rad/m"\n',
                                        r"fixtures\[1\]\.from: the segment .* does not lie on the board outline"),
    "edge segment too short": ('[[fixtures]]\ntype = "edge_spring"\nfrom = ["100 mm", "10 mm"]\n'
                               'to = ["100 mm", "10.01 mm"]\nk_rot = "5 N*m/rad/m"\n',
                               r"fixtures\[1\]\.to: the segment is too short"),
    "edge spring without unit": ('[[fixtures]]\ntype = "edge_spring"\nfrom = ["100 mm", "0 mm"]\n'
                                 'to = ["100 mm", "40 mm"]\nk_rot = 5\n', r"fixtures\[1\]\.k_rot: 5 has no unit"),
    "line mass off the board": ('[[line_masses]]\nname = "l"\nfrom = ["50 mm", "40 mm"]\nto = ["120 mm", "40 mm"]\n'
                                'mass = "5 g"\n', r"line_masses\[0\]\.to: the segment .* leaves the board"),
    "line mass without unit": ('[[line_masses]]\nname = "l"\nfrom = ["50 mm", "40 mm"]\nto = ["90 mm", "40 mm"]\n'
                               'mass = 5\n', r"line_masses\[0\]\.mass: 5 has no unit"),
    "stiffener off the board": ('[[stiffeners]]\nname = "rib"\npath = [["10 mm", "40 mm"], ["90 mm", "40 mm"], '
                                '["90 mm", "95 mm"]]\nEI = "5 N*m^2"\n',
                                r"stiffeners\[0\]\.path\[2\]: the piece .* leaves the board"),
    "stiffener zero EI": ('[[stiffeners]]\nname = "rib"\npath = [["10 mm", "40 mm"], ["90 mm", "40 mm"]]\n'
                          'EI = "0 N*m^2"\n', r"stiffeners\[0\]\.EI: must be positive"),
    "stiffener EI wrong unit": ('[[stiffeners]]\npath = [["10 mm", "40 mm"], ["90 mm", "40 mm"]]\nEI = "5 N*m"\n',
                                r"stiffeners\[0\]\.EI: '5 N\*m' has unit"),
    "region factor zero": ('[[regions]]\nname = "r"\nrect = ["10 mm", "10 mm", "30 mm", "30 mm"]\n'
                           'stiffness_factor = 0\n', r"regions\[0\]\.stiffness_factor: must be > 0"),
    "region factor negative": ('[[regions]]\nname = "r"\nrect = ["10 mm", "10 mm", "30 mm", "30 mm"]\n'
                               'stiffness_factor = -0.5\n', r"regions\[0\]\.stiffness_factor: must be > 0"),
    "region off the board": ('[[regions]]\nname = "r"\npolygon = [["90 mm", "10 mm"], ["130 mm", "10 mm"], '
                             '["110 mm", "30 mm"]]\nstiffness_factor = 1.2\n', r"regions\[0\]: the region reaches off"),
    "region without unit": ('[[regions]]\nname = "r"\nrect = [10, 10, 30, 30]\nstiffness_factor = 1.2\n',
                            r"regions\[0\]\.rect\[0\]: 10 has no unit"),
    "standoff pads overlapping": ('[[fixtures]]\nname = "a"\ntype = "standoff"\nat = ["50 mm", "40 mm"]\n'
                                  '[[fixtures]]\nname = "b"\ntype = "standoff"\nat = ["54.3 mm", "40 mm"]\n',
                                  r"fixtures\[2\]\.at: the standoff's pad overlaps that of standoff 'a' \(centres "
                                  r"4\.3 mm apart, pads 6 and 6 mm\)"),
    "region with neither": ('[[regions]]\nname = "r"\nrect = ["10 mm", "10 mm", "30 mm", "30 mm"]\n',
                            r"regions\[0\]: give stiffness_factor .*, mass .* or both"),
    "region mass negative": ('[[regions]]\nname = "r"\nrect = ["10 mm", "10 mm", "30 mm", "30 mm"]\nmass = "-3 g"\n',
                             r"regions\[0\]\.mass: must not be negative"),
    "region mass target without a mass": ('[[regions]]\nname = "r"\nrect = ["10 mm", "10 mm", "30 mm", "30 mm"]\n'
                                          'stiffness_factor = 1.2\n[[parameters]]\nname = "m"\ntarget = "regions.r.mass"\n'
                                          'bounds = ["1 g", "9 g"]\n',
                                          r"parameters\[0\]\.target: 'regions\.r\.mass' is not a quantity of this structure"),
    "mass and inertia zero": ('[[masses]]\nname = "m"\nat = ["50 mm", "40 mm"]\nmass = "0 g"\n',
                              r"masses\[0\]\.mass: must be positive"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_effect_entries_name_file_and_field(tmp_path, case):
    extra, pattern = BAD[case]
    path = write_board(tmp_path, BASE + "\n" + extra)
    with pytest.raises(BoardError, match=r"^board\.toml: " + pattern):
        load_board(path)


def test_writer_validates_before_writing(base, tmp_path):
    """An effect the board cannot take (a region with factor 1 + s <= 0) is refused with a
    BoardError and leaves no file behind."""
    path, _, cands, _ = base
    c = pick(cands, "region_stiffness", (0.05, 0.05))
    out = tmp_path / "x.toml"
    with pytest.raises(BoardError, match="stiffness_factor: must be > 0"):
        write_enriched(path, [as_effect(c, -1.5)], out_path=out)
    assert not out.exists() and not list(tmp_path.glob(".x.*"))
    with pytest.raises(BoardError, match=r"effects\[0\]\.type: unknown effect type"):
        write_enriched(path, [{"type": "magic", "name": "x", "value": 1.0}], out_path=out)


def test_merged_region_with_a_long_label_is_written_under_a_short_name(base, tmp_path):
    """Two overlapping regions found by diagnose are reported as one whose label joins both (94
    characters on the bench's region_bare_wedge case), longer than a board.toml name may be: the
    enriched file must still load, the entry named within the limit and the full label kept in its
    comment."""
    from pcbdyn.inputs import MAX_NAME

    path, _, cands, _ = base
    c = pick(cands, "region_stiffness", (0.05, 0.05))
    label = "+".join([c.name] * 4)
    assert len(label) > MAX_NAME
    out = write_enriched(path, [{**as_effect(c, 0.5), "name": label}], out_path=tmp_path / "b.toml")
    b = load_board(out)
    assert len(b.regions) == 1 and len(b.regions[0].name) <= MAX_NAME
    assert label in out.read_text()


def test_the_enriched_board_carries_the_fitted_parameters(tmp_path):
    """The diagnosed board is the diagnosed model: its [[parameters]]' targets hold the values diagnose
    fitted (not the declared ones), beside the effects; comments kept."""
    board = load_board(Path(__file__).parents[2] / "examples" / "six_part_card" / "board.toml")
    declared = {p.name: p.value for p in board.parameters}
    fitted = {"E_board": 0.93 * declared["E_board"], "t_PGA": 1.2 * declared["t_PGA"]}
    effect = {"type": "point_mass", "name": "m1", "value": 0.012, "at": (0.05, 0.06)}
    out = board.write_enriched([effect], tmp_path / "board.diagnosed.toml", values=fitted)
    again = load_board(out)
    assert {p.name: p.value for p in again.parameters} == pytest.approx({**declared, **fitted}, rel=1e-12)
    assert again.masses[-1].mass == pytest.approx(0.012) and "found by pcbdyn diagnose" in out.read_text()
    assert board.path.read_text().splitlines()[0] in out.read_text()
