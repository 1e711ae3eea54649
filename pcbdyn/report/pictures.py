"""PNG pictures of mode shapes that an engineer can read.

Each picture shows one mode twice, side by side: the deformed board in 3-D and a top view with x
and y in mm, both coloured by the out-of-plane displacement w scaled so that max |w| = 1, with one
colour bar "w (normalised)". The top view carries the outlines the caller passes as plain data
(dicts ``{"kind", "label", "xy": [[x, y], ...] in metres, "closed"}``: the board and its holes,
parts, fixtures, masses, ...; a single point is a marker), so this module only formats. The title
names the board and configuration (``title``), the mode and its frequency.

The 3-D view is rendered by pyvista/VTK in a child process reading the VTU (off-screen rendering
can kill the process, without a Python error, on machines lacking a working EGL/OSMesa stack);
when that child fails, matplotlib draws the 3-D view too. The page itself is matplotlib either way.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from ..atomic import temporary_folder
from .files import atomic_path

CMAP = "coolwarm"
QUANTITY = "w (normalised)"
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
_OTHER = ("#555555", 1.0, "o", None)


def picture_names(prefix: str, n_modes: int) -> list:
    """File names of the pictures of ``n_modes`` modes: ``<prefix>_01.png``, ..."""
    return [f"{prefix}_{k + 1:02d}.png" for k in range(n_modes)]


def render_pyvista(vtu: Path, out_dir: Path, names: list, quantity: str = "w") -> None:
    """Render the 3-D view of each mode of ``vtu`` (arrays mode_<k>, max |w| = 1), warped and
    coloured by w on [-1, 1] (``quantity`` "magnitude": a structure in 3-D, max |u| = 1, coloured by
    |u| on [0, 1]), to ``out_dir/names[k]`` (run in a child process)."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    grid = pv.read(str(vtu))
    grid.points = grid.points * 1e3  # mm, as the top view
    flat = quantity == "w"
    span = float(np.ptp(grid.points[:, :2] if flat else grid.points, axis=0).max())
    for k, name in enumerate(names, start=1):
        g = grid.copy()
        u = g.point_data[f"mode_{k}"]
        g.point_data["w"] = u[:, 2] if flat else np.linalg.norm(u, axis=1)
        warped = g.warp_by_vector(f"mode_{k}", factor=(0.15 if flat else 0.08) * span)
        p = pv.Plotter(off_screen=True, window_size=(700, 560))
        p.set_background("white")
        p.add_mesh(warped, scalars="w", cmap=CMAP, clim=(-1.0, 1.0) if flat else (0.0, 1.0), show_edges=True,
                   edge_color="gray", line_width=0.4 if flat else 1.5, show_scalar_bar=False)
        p.add_mesh(g.extract_feature_edges(boundary_edges=True, feature_edges=False, manifold_edges=False),
                   color="gray", line_width=1.0)  # the board at rest, for scale
        p.view_isometric()
        p.add_axes(color="black", xlabel="x", ylabel="y", zlabel="z")
        with atomic_path(Path(out_dir) / name) as tmp:
            p.screenshot(str(tmp))
        p.close()


def _view3d_matplotlib(fig, slot, tri, w):
    ax = fig.add_subplot(slot, projection="3d")
    span = max(np.ptp(tri.x), np.ptp(tri.y))
    ax.plot_trisurf(tri, w * 0.15 * span, cmap=CMAP, vmin=-0.15 * span, vmax=0.15 * span, linewidth=0.1,
                    edgecolor="gray", antialiased=True)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zticks([])
    ax.set_box_aspect((np.ptp(tri.x), np.ptp(tri.y), 0.35 * span))
    return ax


def _outline(ax, item, seen: set) -> None:
    color, width, marker, legend = STYLE.get(item["kind"], _OTHER)
    xy = np.asarray(item["xy"], dtype=float).reshape(-1, 2) * 1e3
    label = legend if legend not in seen else None
    seen.add(legend)
    if len(xy) == 1:
        ax.plot(xy[:, 0], xy[:, 1], marker=marker, color=color, markersize=7, linestyle="none", label=label)
        anchor = xy[0]
    else:
        pts = np.vstack([xy, xy[:1]]) if item.get("closed") else xy
        ax.plot(pts[:, 0], pts[:, 1], color=color, linewidth=width, label=label)
        anchor = xy.mean(axis=0) if item.get("closed") else 0.5 * (xy[0] + xy[-1])
    if item.get("label"):
        ax.annotate(item["label"], anchor, xytext=(3, 3), textcoords="offset points", fontsize=7, color=color)


def _trim(image, pad: int = 8):
    """The image without its white margins (kept ``pad`` pixels wide)."""
    ink = np.any(np.asarray(image)[..., :3] < 0.98, axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if rows.size == 0:
        return image
    r0, r1 = max(rows[0] - pad, 0), rows[-1] + pad + 1
    c0, c1 = max(cols[0] - pad, 0), cols[-1] + pad + 1
    return image[r0:r1, c0:c1]


def mode_figure(tri, w, outlines, title: str, view3d=None):
    """The figure of one mode: ``tri`` a matplotlib Triangulation in mm, ``w`` normalised to
    max |w| = 1 at its nodes, ``outlines`` as in the module notes, ``view3d`` the pyvista image
    of the 3-D view (an RGB array) or None to draw it with matplotlib."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import Normalize

    fig = plt.figure(figsize=(13.0, 5.4))
    grid = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 0.04), wspace=0.25)
    if view3d is None:
        _view3d_matplotlib(fig, grid[0, 0], tri, w)
    else:
        ax3 = fig.add_subplot(grid[0, 0])
        ax3.imshow(_trim(view3d))
        ax3.set_axis_off()
    ax = fig.add_subplot(grid[0, 1])
    levels = np.linspace(-1.0, 1.0, 21)
    filled = ax.tricontourf(tri, w, levels=levels, cmap=CMAP, norm=Normalize(-1.0, 1.0))
    ax.tricontour(tri, w, levels=[0.0], colors="k", linewidths=0.8, linestyles="dashed")
    seen = set()
    for item in outlines:
        _outline(ax, item, seen)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("top view (dashed: w = 0)", fontsize=9, pad=14)
    if seen - {None}:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=4, fontsize=8, frameon=False)
    fig.colorbar(filled, cax=fig.add_subplot(grid[0, 2]), label=QUANTITY, ticks=np.linspace(-1, 1, 5))
    fig.suptitle(title)
    return fig


def is_3d(model, outlines=()) -> bool:
    """True for a structure that is not a plate in one plane z = const (a box)."""
    span = float(np.ptp(model.nodes, axis=0).max()) or 1.0
    return any("xyz" in item for item in outlines) or float(np.ptp(model.nodes[:, 2])) > 1e-9 * span


def mode_pictures(vtu: Path, model, frequencies, shapes, out_dir: Path, prefix: str = "mode", title: str = "",
                  outlines=()) -> str:
    """Write ``<prefix>_<k>.png`` per mode (see :func:`picture_names`); ``title`` names the board
    and configuration. Returns the 3-D renderer used ("pyvista" or "matplotlib"). A structure in 3-D
    (outlines in ``xyz``, or nodes off one plane z = const) gets :mod:`.pictures3d`'s pictures."""
    if is_3d(model, outlines):
        from .pictures3d import mode_pictures_3d

        return mode_pictures_3d(vtu, model, frequencies, shapes, out_dir, prefix, title, outlines)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    out_dir = Path(out_dir)
    names = picture_names(prefix, len(frequencies))
    cells = [es.conn for es in model.sets.values() if es.etype in ("quad4", "tri3")]
    tris = [c for c in cells if c.shape[1] == 3] + [c[:, [0, 1, 2]] for c in cells if c.shape[1] == 4]
    tris += [c[:, [0, 2, 3]] for c in cells if c.shape[1] == 4]
    tri = Triangulation(model.nodes[:, 0] * 1e3, model.nodes[:, 1] * 1e3, np.concatenate(tris))
    with temporary_folder("pcbdyn-views") as views:
        renderer = "pyvista" if _render_child(vtu, Path(views), names) else "matplotlib"
        for k, (name, f) in enumerate(zip(names, frequencies)):
            w = shapes[2::6, k]
            w = w / (np.max(np.abs(w)) or 1.0)
            view = plt.imread(Path(views) / name) if renderer == "pyvista" else None
            head = f"{title}: mode {k + 1}, {f:.1f} Hz" if title else f"mode {k + 1}, {f:.1f} Hz"
            fig = mode_figure(tri, w, outlines, head, view)
            with atomic_path(out_dir / name) as tmp:
                fig.savefig(tmp, format="png", dpi=100, bbox_inches="tight", pad_inches=0.15)
            plt.close(fig)
    return renderer


def _render_child(vtu: Path, folder: Path, names: list, quantity: str = "w") -> bool:
    """Run :func:`render_pyvista` in a child process (which dies with this one:
    :func:`pcbdyn.children.die_with_parent`); True when every view was written."""
    code = ("import sys, json; from pathlib import Path; from pcbdyn.children import die_with_parent; "
            "a = json.loads(sys.argv[1]); die_with_parent(a[4]); from pcbdyn.report.pictures import render_pyvista; "
            "render_pyvista(Path(a[0]), Path(a[1]), a[2], a[3])")
    env = {**os.environ, "VTK_DEFAULT_OPENGL_WINDOW": os.environ.get("VTK_DEFAULT_OPENGL_WINDOW",
                                                                       "vtkEGLRenderWindow")}
    try:
        res = subprocess.run([sys.executable, "-c", code, json.dumps([str(vtu), str(folder), names, quantity, os.getpid()])],
                             env=env, capture_output=True, timeout=600)
    except subprocess.TimeoutExpired:
        return False
    return res.returncode == 0 and all((folder / n).is_file() for n in names)
