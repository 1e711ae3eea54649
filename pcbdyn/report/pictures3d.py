"""PNG pictures of the mode shapes of a structure in 3-D (a ribbed box): no view of it is a plane, so
each picture shows the whole deformed structure twice, from the back, right and above (isometric) and
from the opposite side (into an open front), coloured by the displacement along the outward normal over the
largest |u|, with its sign (:func:`.rendering.normal_displacement`: plates moving out red, in blue), with one
colour bar. Ribs (beams) are drawn as lines; the outlines the
structure gives (plain data ``{"kind", "label", "xyz": [[x, y, z], ...] in metres, "closed"}``) label
its plates, ribs, supported edges and masses. The first view is rendered by pyvista from the VTU in a
child process (:func:`pcbdyn.report.rendering.render_pyvista`), with matplotlib in its place when that
fails; the second is matplotlib's. Formatting only."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic import temporary_folder
from ..fe.model import SHELL_TYPES
from .files import save_figure
from .rendering import CMAP, OTHER, QUANTITY_3D, STYLE, normal_displacement, picture_names, render_child, trim

#: warp of the pictures: max |u| drawn as this fraction of the structure's largest extent
WARP = 0.08


def _view(fig, slot, model, shape, signed, outlines, azim: float, title: str):
    """A matplotlib 3-D view of the deformed shells (faces coloured by the mean of ``signed``, the
    normal displacement in [-1, 1], over their nodes) and
    beams, with the outlines' labels, seen from azimuth ``azim``."""
    from matplotlib import colormaps
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    ax = fig.add_subplot(slot, projection="3d")
    xyz = model.nodes * 1e3
    span = float(np.ptp(xyz, axis=0).max())
    u = shape.reshape(-1, 6)[:, :3]
    moved = xyz + WARP * span * u / max(np.linalg.norm(u, axis=1).max(), 1e-300)
    cmap = colormaps[CMAP]
    for es in model.sets.values():
        if es.etype in SHELL_TYPES:
            faces = Poly3DCollection(moved[es.conn], facecolors=cmap(0.5 + 0.5 * signed[es.conn].mean(axis=1)),
                                     edgecolors=(0.4, 0.4, 0.4, 0.35), linewidths=0.2)
            ax.add_collection3d(faces)
        elif es.etype == "beam2":
            ax.add_collection3d(Line3DCollection(moved[es.conn], colors="k", linewidths=1.2))
    for item in outlines:
        color, _, marker, _ = STYLE.get(item["kind"], OTHER)
        pts = np.asarray(item.get("xyz", []), float).reshape(-1, 3) * 1e3
        if len(pts) == 1:
            ax.plot(*pts.T, marker=marker, color=color, markersize=6, linestyle="none")
        if item.get("label") and len(pts) and item["kind"] in ("plate", "mass"):
            ax.text(*pts.mean(axis=0), item["label"], color=color, fontsize=8)
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]), xlabel="x [mm]", ylabel="y [mm]",
           zlabel="z [mm]")
    ax.set_box_aspect(np.maximum(hi - lo, 1e-3 * span))
    ax.view_init(elev=25, azim=azim)
    ax.set_title(title, fontsize=9)
    return ax


def mode_figure_3d(model, shape, signed, outlines, title: str, view3d=None):
    """The figure of one mode: ``shape`` its full-length vector, ``signed`` its normal displacement at
    the nodes (:func:`.rendering.normal_displacement`),
    ``view3d`` the pyvista image of the first view (an RGB array) or None to draw it with matplotlib."""
    import matplotlib.pyplot as plt
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    fig = plt.figure(figsize=(13.0, 5.6))
    grid = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 0.04), wspace=0.2)
    if view3d is None:
        _view(fig, grid[0, 0], model, shape, signed, outlines, 45.0, "from the back, right, above")
    else:
        ax = fig.add_subplot(grid[0, 0])
        ax.imshow(trim(view3d))
        ax.set_axis_off()
        ax.set_title("from the back, right, above", fontsize=9)
    _view(fig, grid[0, 1], model, shape, signed, outlines, -135.0, "from the front, left, above")
    fig.colorbar(ScalarMappable(Normalize(-1.0, 1.0), CMAP), cax=fig.add_subplot(grid[0, 2]), label=QUANTITY_3D,
                 ticks=np.linspace(-1, 1, 5))
    fig.suptitle(title)
    return fig


def mode_pictures_3d(vtu: Path, model, frequencies, shapes, out_dir: Path, prefix: str = "mode", title: str = "",
                     outlines=()) -> str:
    """Write ``<prefix>_<k>.png`` per mode (:func:`pcbdyn.report.pictures.picture_names`). Returns the
    renderer of the first view ("pyvista" or "matplotlib")."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = picture_names(prefix, len(frequencies))
    signed = normal_displacement(model, shapes)
    with temporary_folder("pcbdyn-views") as views:
        renderer = "pyvista" if render_child(vtu, Path(views), names, "normal") else "matplotlib"
        for k, (name, f) in enumerate(zip(names, frequencies)):
            view = plt.imread(Path(views) / name) if renderer == "pyvista" else None
            head = f"{title}: mode {k + 1}, {f:.1f} Hz" if title else f"mode {k + 1}, {f:.1f} Hz"
            fig = mode_figure_3d(model, shapes[:, k], signed[:, k], outlines, head, view)
            save_figure(fig, Path(out_dir) / name, colours=256, dpi=100, bbox_inches="tight", pad_inches=0.15)
    return renderer


def point_map_3d(fig, slot, xyz, values, label: str, cmap: str = "viridis", vmin=None, vmax=None, title: str = ""):
    """Values at points (k, 3) [m] of a structure in 3-D as coloured dots in mm, with a colour bar
    ``label`` (the 3-D counterpart of the maps drawn on a board's outline); returns the axes."""
    ax = fig.add_subplot(slot, projection="3d")
    p = np.asarray(xyz, float) * 1e3
    sc = ax.scatter(p[:, 0], p[:, 1], p[:, 2], c=values, cmap=cmap, vmin=vmin, vmax=vmax, s=28, edgecolors="k",
                    linewidths=0.3, depthshade=False)
    ax.set(xlabel="x [mm]", ylabel="y [mm]", zlabel="z [mm]", title=title)
    ax.set_box_aspect(np.maximum(np.ptp(p, axis=0), 1e-3 * max(np.ptp(p, axis=0).max(), 1e-9)))
    ax.view_init(elev=25, azim=-135)
    fig.colorbar(sc, ax=ax, fraction=0.04, pad=0.08, label=label)
    return ax
