"""The data of the 3-D mode views (pcbdyn.report.view3d) without a browser: displacements and signed
colours decode to the mode shapes (int16 to 1/32767 of the largest motion), a mesh too large for the
budget is coarsened to fit and still carries the shape, box normals face out; and a page that would pass
its size leaves out its optional pictures, naming them."""

import base64
import json

import numpy as np

import pcbdyn.report.html as html
from pcbdyn.fe.generate import rectangle
from pcbdyn.report.rendering import outward_normals
from pcbdyn.report.view3d import Scene, mode_view

A, B = 0.16, 0.10


def decode(text, dtype):
    return np.frombuffer(base64.b64decode(text), dtype=dtype)


def plate_scene(n: int, modes=((1, 1), (2, 1), (1, 3))) -> Scene:
    nodes, conn = rectangle(A, B, n, n)
    scene = Scene("plate", nodes, np.vstack([conn[:, [0, 1, 2]], conn[:, [0, 2, 3]]]))
    for m, k in modes:
        shape = np.zeros((len(nodes), 6))
        shape[:, 2] = 3e-3 * np.sin(m * np.pi * nodes[:, 0] / A) * np.sin(k * np.pi * nodes[:, 1] / B)
        scene.add_mode(shape.ravel())
    return scene


def shape_at(xyz_mm, m, k):
    return np.sin(m * np.pi * xyz_mm[:, 0] / (A * 1e3)) * np.sin(k * np.pi * xyz_mm[:, 1] / (B * 1e3))


def test_small_scene_is_sent_whole_and_decodes_to_the_shapes():
    view = mode_view([plate_scene(16)], ["a", "b", "c"])
    s = view["scenes"][0]
    assert s["coarsened"] is None
    xyz = decode(s["nodes"], np.float32).reshape(-1, 3)
    for (m, k), mode in zip(((1, 1), (2, 1), (1, 3)), s["modes"]):
        u = decode(mode["u"], np.int16).reshape(-1, 3) / 32767
        np.testing.assert_allclose(u[:, 2], shape_at(xyz, m, k), atol=1.0 / 32767)
        assert np.all(u[:, :2] == 0)
        colour = decode(mode["s"], np.int8) / 127  # outward normal of a flat board: +z, so w itself
        np.testing.assert_allclose(colour, shape_at(xyz, m, k), atol=1.0 / 127)
        assert colour.min() < -0.9 or m == k == 1  # signed: the (2,1) and (1,3) modes go both ways


def test_large_scene_is_coarsened_under_the_budget_and_keeps_the_shape():
    budget = 300_000
    view = mode_view([plate_scene(150)], ["a", "b", "c"], max_bytes=budget)  # 22801 nodes
    s = view["scenes"][0]
    assert len(json.dumps(view)) < budget
    n_drawn, n_kept = s["coarsened"]
    assert n_drawn == 151 * 151 and 1000 < n_kept < n_drawn / 4
    xyz = decode(s["nodes"], np.float32).reshape(-1, 3)
    assert len(xyz) == n_kept and decode(s["tris"], np.uint32).max() < n_kept
    u = decode(s["modes"][2]["u"], np.int16).reshape(-1, 3)[:, 2] / 32767
    ref = shape_at(xyz, 1, 3)  # a cluster carries its nodes' mean motion, at their mean place
    assert np.abs(u / np.abs(u).max() - ref / np.abs(ref).max()).max() < 0.03


def test_box_normals_face_out():
    """A unit cube's six faces meshed with mixed orientations: every node normal points away from the centre."""
    nodes, conn = rectangle(1.0, 1.0, 4, 4)
    faces, tris = [], []
    for axis in range(3):
        for side, flip in ((0.0, True), (1.0, False)):
            p = np.roll(np.column_stack([nodes[:, :2], np.full(len(nodes), side)]), axis + 1, axis=1)
            t = np.vstack([conn[:, [0, 1, 2]], conn[:, [0, 2, 3]]]) + len(faces) * len(nodes)
            tris.append(t[:, ::-1] if flip else t)
            faces.append(p)
    xyz = np.vstack(faces)
    n = outward_normals(xyz, np.vstack(tris))
    assert np.all(np.einsum("ij,ij->i", n, xyz - 0.5) > 0)


def test_a_page_over_its_size_leaves_out_optional_pictures_and_names_them(tmp_path, monkeypatch):
    rng = np.random.default_rng(0)
    from PIL import Image

    paths = []
    for k in range(6):  # noise: about 120 kB each, whatever the compression
        p = tmp_path / "png" / f"mode_{k + 1:02d}.png"
        p.parent.mkdir(exist_ok=True)
        Image.fromarray(rng.integers(0, 255, (200, 200, 3), dtype=np.uint8)).save(p)
        paths.append(p)
    monkeypatch.setattr(html, "PAGE_BYTES", 600_000)
    page = html.Page("t").pictures("kept", paths[:2]).pictures("shapes", paths[2:], optional=True)
    out = page.write(tmp_path / "report.html")
    text = out.read_text()
    assert len(text.encode()) <= 600_000
    kept = text.count("data:image/png;base64,")
    assert 2 <= kept < 6 and text.count('<figure>') == kept
    left = [f"png/mode_{k:02d}.png" for k in range(kept + 1, 7)]
    assert f"{len(left)} picture(s) left out to keep the page under 0.6 MB" in text and ", ".join(left) in text
    monkeypatch.setattr(html, "PAGE_BYTES", 100_000)  # pictures that are not optional are never left out
    text = html.Page("t").pictures("kept", paths[:2]).write(tmp_path / "r2.html").read_text()
    assert text.count("data:image/png;base64,") == 2 and "left out" not in text
