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

from pathlib import Path

import numpy as np

from ..atomic import temporary_folder
from ..fe.model import SHELL_TYPES
from .files import save_figure
from .pictures3d import mode_pictures_3d
from .rendering import CMAP, OTHER, QUANTITY, STYLE, picture_names, render_child, trim

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
    color, width, marker, legend = STYLE.get(item["kind"], OTHER)
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
        ax3.imshow(trim(view3d))
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
        return mode_pictures_3d(vtu, model, frequencies, shapes, out_dir, prefix, title, outlines)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    out_dir = Path(out_dir)
    names = picture_names(prefix, len(frequencies))
    cells = [es.conn for es in model.sets.values() if es.etype in SHELL_TYPES]
    tris = [c for c in cells if c.shape[1] == 3] + [c[:, [0, 1, 2]] for c in cells if c.shape[1] == 4]
    tris += [c[:, [0, 2, 3]] for c in cells if c.shape[1] == 4]
    tri = Triangulation(model.nodes[:, 0] * 1e3, model.nodes[:, 1] * 1e3, np.concatenate(tris))
    with temporary_folder("pcbdyn-views") as views:
        renderer = "pyvista" if render_child(vtu, Path(views), names) else "matplotlib"
        for k, (name, f) in enumerate(zip(names, frequencies)):
            w = shapes[2::6, k]
            w = w / (np.max(np.abs(w)) or 1.0)
            view = plt.imread(Path(views) / name) if renderer == "pyvista" else None
            head = f"{title}: mode {k + 1}, {f:.1f} Hz" if title else f"mode {k + 1}, {f:.1f} Hz"
            fig = mode_figure(tri, w, outlines, head, view)
            save_figure(fig, out_dir / name, colours=256, dpi=100, bbox_inches="tight", pad_inches=0.15)
    return renderer


