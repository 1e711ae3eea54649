"""PNG pictures of mode shapes.

pyvista/VTK off-screen rendering can kill the process (no Python error) on machines without a
working EGL/OSMesa stack, so it runs in a child process reading the VTU; when that child fails,
the pictures are drawn with matplotlib (filled contours of w on the board) instead.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from .files import atomic_path


def render_pyvista(vtu: Path, out_dir: Path, names: list, titles: list) -> None:
    """Render each mode of ``vtu`` (arrays mode_<k>) warped and coloured by w (run in a child)."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    grid = pv.read(str(vtu))
    span = float(np.ptp(grid.points[:, :2], axis=0).max())
    for k, (name, title) in enumerate(zip(names, titles), start=1):
        g = grid.copy()
        g.point_data["w"] = g.point_data[f"mode_{k}"][:, 2]
        warped = g.warp_by_vector(f"mode_{k}", factor=0.15 * span)
        p = pv.Plotter(off_screen=True, window_size=(800, 600))
        p.add_mesh(warped, scalars="w", cmap="coolwarm", show_edges=True, edge_color="gray", line_width=0.5,
                   show_scalar_bar=False)
        p.add_text(title, font_size=12)
        p.view_isometric()
        with atomic_path(out_dir / name) as tmp:
            p.screenshot(str(tmp))
        p.close()


def render_matplotlib(nodes, cells, shapes, out_dir: Path, names: list, titles: list) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    tris = [c for c in cells if c.shape[1] == 3] + [c[:, [0, 1, 2]] for c in cells if c.shape[1] == 4]
    tris += [c[:, [0, 2, 3]] for c in cells if c.shape[1] == 4]
    tri = Triangulation(nodes[:, 0] * 1e3, nodes[:, 1] * 1e3, np.concatenate(tris))
    for k, (name, title) in enumerate(zip(names, titles)):
        w = shapes[2::6, k]
        w = w / (np.max(np.abs(w)) or 1.0)
        fig, ax = plt.subplots(figsize=(6, 5))
        ax.tricontourf(tri, w, levels=np.linspace(-1, 1, 21), cmap="coolwarm")
        ax.tricontour(tri, w, levels=[0.0], colors="k", linewidths=1.0)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(title)
        with atomic_path(out_dir / name) as tmp:
            fig.savefig(tmp, format="png", dpi=100)
        plt.close(fig)


def mode_pictures(vtu: Path, model, frequencies, shapes, out_dir: Path, prefix: str = "mode") -> str:
    """Write ``<prefix>_<k>.png`` per mode; returns the renderer used ("pyvista" or "matplotlib")."""
    out_dir = Path(out_dir)
    names = [f"{prefix}_{k + 1:02d}.png" for k in range(len(frequencies))]
    titles = [f"mode {k + 1}: {f:.1f} Hz" for k, f in enumerate(frequencies)]
    code = ("import sys, json; from pathlib import Path; from pcbdyn.report.pictures import render_pyvista; "
            "a = json.loads(sys.argv[1]); render_pyvista(Path(a[0]), Path(a[1]), a[2], a[3])")
    import json

    env = {**os.environ, "VTK_DEFAULT_OPENGL_WINDOW": os.environ.get("VTK_DEFAULT_OPENGL_WINDOW",
                                                                       "vtkEGLRenderWindow")}
    try:
        res = subprocess.run([sys.executable, "-c", code, json.dumps([str(vtu), str(out_dir), names, titles])],
                             env=env, capture_output=True, timeout=600)
        if res.returncode == 0:
            return "pyvista"
    except subprocess.TimeoutExpired:
        pass
    cells = [es.conn for es in model.sets.values() if es.etype in ("quad4", "tri3")]
    render_matplotlib(model.nodes, cells, shapes, out_dir, names, titles)
    return "matplotlib"
