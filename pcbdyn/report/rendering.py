"""What the mode pictures of flat boards (:mod:`.pictures`) and of structures in 3-D (:mod:`.pictures3d`)
share: colours and outline styles, file names, and the pyvista/VTK rendering of the 3-D views, run in a
child process that reads the VTU (off-screen rendering can kill the process, without a Python error, on
machines lacking a working EGL/OSMesa stack)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from .files import atomic_path

CMAP = "coolwarm"
QUANTITY = "w (normalised)"
#: what a structure in 3-D is coloured by: the displacement along the outward normal over the largest |u|
QUANTITY_3D = "normal displacement (outward, / max |u|)"
#: how each kind of outline is drawn in the top view: colour, line width, marker, legend label
STYLE = {
    "board": ("black", 1.2, "o", None),
    "part": ("#1b7837", 1.2, "s", "parts"),
    "fixture": ("#7b3294", 2.4, "^", "fixtures"),
    "mass": ("black", 1.0, "X", "masses"),
    "line mass": ("#555555", 2.0, "o", "line masses"),
    "stiffener": ("#b35806", 2.4, "o", "stiffeners"),
    "region": ("#555555", 1.0, "o", "regions"),
}
OTHER = ("#555555", 1.0, "o", None)


def surface_cells(model):
    """(triangles (t, 3), beam segments (b, 2)) of the model's shells (quads split in two) and beams."""
    tris, lines = [np.zeros((0, 3), np.int64)], [np.zeros((0, 2), np.int64)]
    for es in model.sets.values():
        if es.etype == "tri3":
            tris.append(es.conn)
        elif es.etype == "quad4":
            tris += [es.conn[:, [0, 1, 2]], es.conn[:, [0, 2, 3]]]
        elif es.etype == "beam2":
            lines.append(es.conn)
    return np.concatenate(tris), np.concatenate(lines)


def outward_normals(xyz, tris) -> np.ndarray:
    """Unit normals at the nodes (n, 3; zero off the shells): the sum of the normals of the triangles
    around each node, each turned to point away from the structure's centroid, so that a box's plates
    all face out whatever their declared orientation (a flat board's stay as meshed, +z)."""
    xyz = np.asarray(xyz, float)
    a, b, c = xyz[tris[:, 0]], xyz[tris[:, 1]], xyz[tris[:, 2]]
    n = np.cross(b - a, c - a)
    span = float(np.ptp(xyz, axis=0).max()) if len(xyz) else 1.0
    away = np.einsum("ij,ij->i", n, (a + b + c) / 3.0 - xyz.mean(axis=0))
    n[away < -1e-6 * (span or 1.0) * np.linalg.norm(n, axis=1)] *= -1.0
    out = np.zeros_like(xyz)
    for k in range(3):
        np.add.at(out, tris[:, k], n)
    return out / np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-300)


def normal_displacement(model, shapes) -> np.ndarray:
    """(n_nodes, n_modes): each mode's displacement along the outward normal (:func:`outward_normals`),
    over the mode's largest |u| (signed, within [-1, 1])."""
    u = np.asarray(shapes).reshape(model.n_nodes, 6, -1)[:, :3]
    normals = outward_normals(model.nodes, surface_cells(model)[0])
    return np.einsum("ikm,ik->im", u, normals) / np.maximum(np.linalg.norm(u, axis=1).max(axis=0), 1e-300)


def picture_names(prefix: str, n_modes: int) -> list:
    """File names of the pictures of ``n_modes`` modes: ``<prefix>_01.png``, ..."""
    return [f"{prefix}_{k + 1:02d}.png" for k in range(n_modes)]


def render_pyvista(vtu: Path, out_dir: Path, names: list, quantity: str = "w") -> None:
    """Render the 3-D view of each mode of ``vtu`` (arrays mode_<k>, max |w| = 1), warped and
    coloured by w on [-1, 1] (``quantity`` "normal": a structure in 3-D, max |u| = 1, coloured by its
    arrays normal_<k>, :func:`normal_displacement`), to ``out_dir/names[k]`` (run in a child process)."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    grid = pv.read(str(vtu))
    grid.points = grid.points * 1e3  # mm, as the top view
    flat = quantity == "w"
    span = float(np.ptp(grid.points[:, :2] if flat else grid.points, axis=0).max())
    for k, name in enumerate(names, start=1):
        g = grid.copy()
        u = g.point_data[f"mode_{k}"]
        g.point_data["w"] = u[:, 2] if flat else g.point_data[f"normal_{k}"]
        warped = g.warp_by_vector(f"mode_{k}", factor=(0.15 if flat else 0.08) * span)
        p = pv.Plotter(off_screen=True, window_size=(700, 560))
        p.set_background("white")
        p.add_mesh(warped, scalars="w", cmap=CMAP, clim=(-1.0, 1.0), show_edges=True,
                   edge_color="gray", line_width=0.4 if flat else 1.5, show_scalar_bar=False)
        p.add_mesh(g.extract_feature_edges(boundary_edges=True, feature_edges=False, manifold_edges=False),
                   color="gray", line_width=1.0)  # the board at rest, for scale
        p.view_isometric()
        p.add_axes(color="black", xlabel="x", ylabel="y", zlabel="z")
        with atomic_path(Path(out_dir) / name) as tmp:
            p.screenshot(str(tmp))
        p.close()


def trim(image, pad: int = 8):
    """The image without its white margins (kept ``pad`` pixels wide)."""
    ink = np.any(np.asarray(image)[..., :3] < 0.98, axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if rows.size == 0:
        return image
    r0, r1 = max(rows[0] - pad, 0), rows[-1] + pad + 1
    c0, c1 = max(cols[0] - pad, 0), cols[-1] + pad + 1
    return image[r0:r1, c0:c1]


def render_child(vtu: Path, folder: Path, names: list, quantity: str = "w") -> bool:
    """Run :func:`render_pyvista` in a child process (which dies with this one:
    :func:`pcbdyn.children.die_with_parent`); True when every view was written."""
    code = ("import sys, json; from pathlib import Path; from pcbdyn.children import die_with_parent; "
            "a = json.loads(sys.argv[1]); die_with_parent(a[4]); from pcbdyn.report.rendering import render_pyvista; "
            "render_pyvista(Path(a[0]), Path(a[1]), a[2], a[3])")
    env = {**os.environ, "VTK_DEFAULT_OPENGL_WINDOW": os.environ.get("VTK_DEFAULT_OPENGL_WINDOW",
                                                                       "vtkEGLRenderWindow")}
    try:
        res = subprocess.run([sys.executable, "-c", code, json.dumps([str(vtu), str(folder), names, quantity, os.getpid()])],
                             env=env, capture_output=True, timeout=600)
    except subprocess.TimeoutExpired:
        return False
    return res.returncode == 0 and all((folder / n).is_file() for n in names)
