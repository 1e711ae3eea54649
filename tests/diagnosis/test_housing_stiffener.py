"""Stiffeners on a housing's plates (issue 37: "the search covers boxes as it covers boards"): the lines the
search tries on each plate of a box, seen in the plate's own plane (pcbdyn.diagnosis.plate_view), and a rib
that a housing's description lacks, found on its wall.

- A plate is the same plate wherever it stands: a rib candidate on a one-plate box in the x-y plane (the
  board's path) and on the same plate stood up as a wall x = 0 (the plate's view) shifts every frequency by
  the same factor (within the two meshes' own difference), and the search tries as many lines on each.
- On the example housing the candidates stand on the inside of each plate, and a candidate along a
  declared rib's line reproduces that rib's frequencies within the two beam models' difference.
- A 4 x 12 mm aluminium bar glued inside the housing's left wall, y = 20 to 140 mm at z = 30 mm, and left
  out of the box.toml handed to diagnose (test: the example meshed at 8 mm, pcbdyn's noise; model 16 mm):
  found as a stiffener on that wall within the benchmark's 30 mm of the bar's ends and 30 % of its EI
  (its ends and section fitted on the housing meshed along it, :mod:`pcbdyn.diagnosis.geometry_fit`: they
  were walked on the model's own cells before, which left EI 36 % low), and the enriched box.toml
  declares it as a rib of the section found.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.box import load_box
from pcbdyn.cli import main
from pcbdyn.diagnosis.catalogue import kind
from pcbdyn.diagnosis.layout import from_structure
from pcbdyn.fe.modal import solve_modes

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "box"))
from box_helpers import EXAMPLE, POINTS, edited, plate_box, supports  # noqa: E402

A, B = 180.0, 120.0  # [mm] the plate's sides along u and v


def test_a_rib_on_a_plate_stood_up_as_a_wall_is_the_rib_on_the_flat_plate(tmp_path):
    """The two boxes are meshed apart (gmsh in space), so their plain frequencies differ a little: the rib's
    shifts agree within three times that difference."""
    rib = kind("stiffener")
    shifts, counts, plain = [], [], []
    for name, axes, to3 in (("flat", ((1, 0, 0), (0, 1, 0)), lambda s, t: [s, t, 0.0]),
                            ("wall", ((0, 1, 0), (0, 0, 1)), lambda s, t: [0.0, s, t])):
        pm = load_box(plate_box(tmp_path, A, B, 2, supports("p", "clamped", ("v0",)), name=f"{name}.toml",
                                axes=axes)).build()
        layout = from_structure(pm)
        assert layout.planar == (name == "flat")
        ends = 1e-3 * np.array([to3(0.2 * A, 0.0), to3(0.7 * A, B)])  # an oblique line across the cells
        if layout.planar:
            c = rib.candidate(layout, "t", *ends[:, :2])
        else:
            c = rib.candidate(layout, "t", *layout.plate_view("p")[1].flat(ends), plate="p")
            assert np.allclose(c.geometry["path"], ends, atol=1e-12)  # lifted back to where it was asked
        plain.append(solve_modes(pm.model, n_modes=6).frequencies)
        shifts.append(solve_modes(rib.apply(pm.model, c, 2.0), n_modes=6).frequencies / plain[-1])
        counts.append(len(rib.generate(layout)))
    assert counts[0] == counts[1] > 0
    assert np.all(shifts[0] > 1.05)  # a 2 N m^2 rib stiffens every mode of the 2 mm plate
    meshes = float(np.abs(plain[1] / plain[0] - 1.0).max())
    assert meshes < 1e-3
    assert np.abs(shifts[1] / shifts[0] - 1.0).max() <= 3.0 * meshes + 1e-9


def test_a_housing_meshed_along_a_rib_found_on_its_wall_puts_the_rib_on_nodes(tmp_path):
    """``following`` (the domain interface): the wall's mesh gains element edges along an oblique line,
    so the rib placed on it ends every piece on a node (one shape-function weight of 1), as it does on a
    board meshed along a line; moved in the wall's plane (:meth:`along`), it stays on the wall."""
    from pcbdyn.diagnosis.catalogue import place
    from pcbdyn.diagnosis.stiffener import in_plane

    rib = kind("stiffener")
    box = load_box(plate_box(tmp_path, A, B, 2, supports("p", "clamped", ("v0",)), axes=((0, 1, 0), (0, 0, 1))))
    layout = from_structure(box.build())
    st = layout.plate_view("p")[1].flat(1e-3 * np.array([[0.0, 0.23 * A, 0.11 * B], [0.0, 0.71 * A, 0.87 * B]]))
    embedded = rib.candidate(layout, "t", *st, plate="p")
    assert not np.allclose(np.sort(embedded.data["weights"], axis=2)[:, :, -1], 1.0)  # inside the cells

    followed = from_structure(box.following([embedded.geometry["path"]]).build())
    on = place(followed, embedded)
    assert np.allclose(np.sort(on.data["weights"], axis=2)[:, :, -1], 1.0, atol=1e-9)
    assert in_plane(on) == pytest.approx(st, abs=1e-12) and on.name == embedded.name
    shifted = rib.along(on, st + [0.01, -0.02])
    assert np.abs(shifted.geometry["path"][:, 0]).max() < 1e-12  # on the wall x = 0
    assert in_plane(shifted) == pytest.approx(st + [0.01, -0.02], abs=1e-12)
    assert np.asarray(shifted.geometry["path"]) == pytest.approx(followed.plate_view("p")[1].lift(st + [0.01, -0.02]))


def test_candidates_stand_inside_the_housing_and_follow_a_declared_rib(tmp_path):
    """Each plate's candidates stand on the side of its normal towards the box's inside (the upper plate's
    -z, the left wall's +x); a candidate along the upper plate's line y = 40 mm with the EI of a 4 x 12 mm
    aluminium rib (its section's height) shifts the frequencies as that rib declared does, within 3 %
    (the declared rib is a Timoshenko beam on the nodes with its own torsion constant)."""
    base = load_box(EXAMPLE).build()
    layout = from_structure(base)
    cands = kind("stiffener").generate(layout)
    inward = {"upper": [0, 0, -1], "left": [1, 0, 0], "right": [-1, 0, 0], "back": [0, -1, 0]}
    assert {c.data["plate"] for c in cands} == set(inward)
    for c in cands:
        assert np.allclose(c.data["normal"], inward[c.data["plate"]], atol=1e-12)
    text = EXAMPLE.read_text().replace("[[supports]]", '[[ribs]]\nname = "glued"\nplate = "upper"\nfrom = ["0 mm", "40 mm"]\n'
                                       'to = ["200 mm", "40 mm"]\nheight = "4 mm"\nwidth = "12 mm"\nside = "-n"\n\n[[supports]]', 1)
    ribbed = tmp_path / "ribbed.toml"
    ribbed.write_text(text)
    frame = layout.plate_view("upper")[1]
    c = kind("stiffener").candidate(layout, "t", *frame.flat([[0.0, 0.04, 0.12], [0.2, 0.04, 0.12]]), plate="upper")
    f0 = solve_modes(base.model, n_modes=8).frequencies
    declared = solve_modes(load_box(ribbed).build().model, n_modes=8).frequencies
    embedded = solve_modes(kind("stiffener").apply(base.model, c, 70e9 * 0.012 * 0.004**3 / 12), n_modes=8).frequencies
    assert embedded == pytest.approx(declared, rel=0.03)
    moved = np.abs(declared / f0 - 1) > 0.02
    assert moved.sum() >= 3 and np.all(np.sign(embedded - f0)[moved] == np.sign(declared - f0)[moved])


def test_a_bar_glued_inside_a_housing_wall_is_found(tmp_path):
    from pcbdyn.testdata import Noise, read_points_csv, write_uff
    from pcbdyn.testdata.simulate import simulate_on_model

    model = edited(tmp_path, {"box.mesh_size": '"16 mm"'}, name="model.toml")
    truth = edited(tmp_path, {"box.mesh_size": '"8 mm"'}, remove=("parameters",), name="truth.toml")
    bar = ('[[ribs]]\nname = "bar"\nplate = "left"\nfrom = ["20 mm", "30 mm"]\nto = ["140 mm", "30 mm"]\nheight = "4 mm"\n'
           'width = "12 mm"\nside = "+n"\n\n[[supports]]')
    truth.write_text(truth.read_text().replace("[[supports]]", bar, 1))
    pm = load_box(truth).build()
    points, dofs = read_points_csv(POINTS)
    write_uff(tmp_path / "t.uff", simulate_on_model(pm.model, solve_modes(pm.model, n_modes=10), points, dofs,
                                                    noise=Noise(0.2, 2.0, 0.0), seed=5, tol=0.02))
    js = tmp_path / "d.json"
    r = CliRunner().invoke(main, ["diagnose", str(model), str(tmp_path / "t.uff"), "--noise", "f=0.2,shape=2", "--kinds",
                                  "stiffener,point_mass", "--json", str(js), "--out", str(tmp_path / "out")])
    assert r.exit_code == 0, r.output
    data = json.loads(js.read_text())
    ribs = [e for e in data["effects"] if e["type"] == "stiffener"]
    assert len(ribs) == 1 and ribs[0]["plate"] == "left"
    path = np.asarray(ribs[0]["path_mm"], float)
    for end in ([0.0, 20.0, 30.0], [0.0, 140.0, 30.0]):  # the bar's ends lie within 30 mm of the line found
        t = np.clip((np.asarray(end) - path[0]) @ (path[1] - path[0]) / np.sum((path[1] - path[0]) ** 2), 0.0, 1.0)
        assert np.linalg.norm(path[0] + t * (path[1] - path[0]) - end) < 30.0
    assert ribs[0]["magnitude"] == pytest.approx(70e9 * 0.012 * 0.004**3 / 12, rel=0.30)  # its EI, 4.48 N m^2
    assert data["after"]["max_freq_error_pct"] < data["parameters_only"]["max_freq_error_pct"]
    enriched = load_box(data["enriched_board"])
    found = next(r for r in enriched.ribs if r.name not in {q.name for q in load_box(model).ribs})
    h = 1e-3 * ribs[0]["section_height_mm"]  # the section the fit ended on, declared as it is
    assert found.plate == "left" and found.height == pytest.approx(h, rel=1e-4)
    assert found.width == pytest.approx(12.0 * ribs[0]["magnitude"] / (70e9 * h**3), rel=1e-3)
