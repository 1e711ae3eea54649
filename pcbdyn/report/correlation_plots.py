"""Pictures of a test-model correlation (matplotlib, PNG, written atomically).

- MAC matrix (thesis eq. 2.3) with the chosen pairs framed;
- the 45-degree plot: model against test frequency of each pair, with +-5 % lines;
- per pair, the model shape (filled contours on the FE mesh, nodal line solid) with the test shape
  as squares at the measurement points (same colour scale after the modal scale factor, nodal
  line dashed), on the board outline: a square whose colour differs from its surroundings marks
  a point where test and model disagree;
- COMAC per point (thesis eq. 2.4) on the board outline.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .files import PLOT, pyplot, save_figure
from .labels import place_labels

CMAP = "coolwarm"


def mac_matrix(path, M, pairs, f_test, f_model, title: str = "MAC (pairs framed in red)",
               rows: str = "test mode") -> None:
    """The MAC matrix (``rows`` modes down, model modes across) with values and the pairs framed."""
    plt = pyplot()
    from matplotlib.patches import Rectangle

    M = np.asarray(M)
    nt, na = M.shape
    fig, ax = plt.subplots(figsize=(1.0 + 0.55 * na, 1.2 + 0.5 * nt))
    im = ax.imshow(M, vmin=0.0, vmax=1.0, cmap="Blues", origin="upper")
    for i in range(nt):
        for j in range(na):
            ax.text(j, i, f"{M[i, j]:.2f}", ha="center", va="center", fontsize=7,
                    color="white" if M[i, j] > 0.6 else "black")
    for p in pairs:
        ax.add_patch(Rectangle((p.model - 0.5, p.test - 0.5), 1, 1, fill=False, edgecolor="red", linewidth=2))
    ax.set_xticks(range(na), [f"{j + 1}\n{f:.0f}" for j, f in enumerate(f_model)], fontsize=7)
    ax.set_yticks(range(nt), [f"{i + 1}: {f:.0f}" for i, f in enumerate(f_test)], fontsize=7)
    ax.set_xlabel("model mode / frequency [Hz]")
    ax.set_ylabel(f"{rows}: frequency [Hz]")
    ax.set_title(title)
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
    save_figure(fig, path, **PLOT)


def frequency_plot(path, pairs, band_pct: float = 5.0) -> None:
    """Model against test frequency of each pair, on the 45-degree line with +-``band_pct`` lines;
    each point is labelled test/model mode and coloured by its MAC."""
    plt = pyplot()
    ft = np.array([p.f_test for p in pairs])
    fa = np.array([p.f_model for p in pairs])
    macs = np.array([p.mac_combined for p in pairs])
    top = 1.08 * max(ft.max(), fa.max())
    fig, ax = plt.subplots(figsize=(5.5, 5.0))
    line = np.array([0.0, top])
    ax.plot(line, line, "k-", linewidth=1, label="f_model = f_test")
    for s in (1 + band_pct / 100, 1 - band_pct / 100):
        ax.plot(line, s * line, "k:", linewidth=0.8)
    ax.plot([], [], "k:", linewidth=0.8, label=f"+-{band_pct:g} %")
    sc = ax.scatter(ft, fa, c=macs, cmap="viridis", vmin=min(0.5, float(macs.min())), vmax=1.0, s=40, zorder=3,
                    edgecolors="k")
    for p in pairs:
        ax.annotate(f"{p.test + 1}/{p.model + 1}", (p.f_test, p.f_model), textcoords="offset points",
                    xytext=(5, -10), fontsize=7)
    ax.set_xlim(0, top)
    ax.set_ylim(0, top)
    ax.set_aspect("equal")
    ax.set_xlabel("test frequency [Hz]")
    ax.set_ylabel("model frequency [Hz]")
    ax.set_title("paired frequencies (labels: test/model mode)")
    ax.legend(loc="upper left", fontsize=8)
    fig.colorbar(sc, ax=ax, fraction=0.046, pad=0.04, label="MAC")
    save_figure(fig, path, **PLOT)


def draw_outline(ax, outline) -> None:
    """Draw the board outline and holes [mm], with a margin so that markers on the edges show whole."""
    for poly in [outline.vertices, *outline.holes]:
        v = np.vstack([poly, poly[:1]]) * 1e3
        ax.plot(v[:, 0], v[:, 1], "k-", linewidth=1.2)
    lo, hi = (np.asarray(b) * 1e3 for b in outline.bbox)
    pad = 0.04 * float(np.max(hi - lo))
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)


def shell_triangulation(model):
    """The model's shells as one matplotlib triangulation in mm (quads split in two), for maps."""
    from matplotlib.tri import Triangulation

    tris = []
    for es in model.sets.values():
        if es.etype == "quad4":
            tris += [es.conn[:, [0, 1, 2]], es.conn[:, [0, 2, 3]]]
        elif es.etype == "tri3":
            tris.append(es.conn)
    return Triangulation(model.nodes[:, 0] * 1e3, model.nodes[:, 1] * 1e3, np.concatenate(tris))


def _point_triangulation(xy):
    """Delaunay triangulation of the points, or None when they are too few or collinear."""
    from matplotlib.tri import TriAnalyzer, Triangulation

    if len(xy) < 3 or np.linalg.matrix_rank(xy - xy.mean(0)) < 2:
        return None
    try:
        tri = Triangulation(xy[:, 0], xy[:, 1])
    except (ValueError, RuntimeError):
        return None
    tri.set_mask(TriAnalyzer(tri).get_flat_tri_mask(min_circle_ratio=0.1))  # slivers along the hull
    return tri


def shape_overlays(out_dir, model, outline, pairs, test_xy, test_w, model_at_test, model_w, prefix="pair"):
    """One PNG per pair: model shape ``model_w`` (n_nodes, n_pairs: w at the FE nodes) as filled
    contours, the test shape ``test_w`` (n_points, n_pairs: z components at ``test_xy`` [m]) as
    coloured markers. The test is scaled by the modal scale factor onto ``model_at_test`` (the
    model at the test DOFs), then both by the model's largest value at the points, so equal colours
    mean equal motion. Returns the file names."""
    plt = pyplot()
    tri = shell_triangulation(model)
    xy = np.asarray(test_xy) * 1e3
    w_abs = np.abs(np.asarray(test_w))
    moving = w_abs.max(axis=1) > 1e-9 * (w_abs.max() or 1.0)  # points at rest (held edges) bend no nodal line
    ptri = _point_triangulation(xy[moving])
    levels = np.linspace(-1.0, 1.0, 21)
    names = []
    for k, p in enumerate(pairs):
        a, x = model_at_test[:, k], test_w[:, k]
        msf = float(a @ x) / float(x @ x) if x @ x > 0 else 0.0
        scale = np.max(np.abs(a)) or 1.0
        xs, ws = msf * x / scale, model_w[:, k] / scale
        fig, ax = plt.subplots(figsize=(6.0, 5.6))
        cf = ax.tricontourf(tri, np.clip(ws, -1, 1), levels=levels, cmap=CMAP)
        ax.tricontour(tri, ws, levels=[0.0], colors="k", linewidths=1.2)
        if ptri is not None:
            ax.tricontour(ptri, xs[moving], levels=[0.0], colors="k", linewidths=1.2, linestyles="--")
        ax.scatter(xy[:, 0], xy[:, 1], c=np.clip(xs, -1, 1), cmap=CMAP, vmin=-1, vmax=1, s=70, marker="s",
                   edgecolors="k", linewidths=1.0, zorder=3)
        draw_outline(ax, outline)
        ax.plot([], [], "k-", label="model nodal line")
        ax.plot([], [], "k--", label="test nodal line")
        ax.scatter([], [], c="w", marker="s", edgecolors="k", label="test points (colour: test)")
        fig.colorbar(cf, ax=ax, fraction=0.046, pad=0.04, ticks=[-1, -0.5, 0, 0.5, 1],
                     label="w / largest model |w| at the points")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=7, frameon=False)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        combo = f" (+ {', '.join(str(c + 1) for c in p.cluster if c != p.model)})" if len(p.cluster) > 1 else ""
        ax.set_title(f"test {p.test + 1}: {p.f_test:.1f} Hz  /  model {p.model + 1}{combo}: {p.f_model:.1f} Hz\n"
                     f"df = {p.df_pct:+.2f} %, MAC = {p.mac_combined:.3f}", fontsize=10)
        name = f"{prefix}_{k + 1:02d}_test{p.test + 1}_model{p.model + 1}.png"
        save_figure(fig, Path(out_dir) / name, **PLOT)
        names.append(name)
    return names


def comac_map(path, outline, xy, values, labels, lines=None) -> None:
    """COMAC per measured DOF at its point on the board outline (low = test and model disagree), over the
    test's wireframe ``lines`` (n, 2, 3) [m] when given; on a structure in 3-D (``outline`` None, ``xy`` the
    points (k, 3)) a 3-D map."""
    plt = pyplot()
    lo = min(0.9, float(np.min(values)))
    if outline is None:
        from .pictures3d import point_map_3d

        fig = plt.figure(figsize=(7.0, 6.0))
        point_map_3d(fig, 111, xy, values, "COMAC", "RdYlGn", lo, 1.0, "COMAC per point over the pairs")
        save_figure(fig, path, **PLOT)
        return
    xy = np.asarray(xy) * 1e3
    fig, ax = plt.subplots(figsize=(6.0, 5.6))
    draw_outline(ax, outline)  # lo spreads the usual 0.9-1 range over the colours
    if lines is not None:
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(np.asarray(lines)[:, :, :2] * 1e3, colors="0.55", linewidths=0.8, zorder=2))
    sc = ax.scatter(xy[:, 0], xy[:, 1], c=values, cmap="RdYlGn", vmin=lo, vmax=1.0, s=60, edgecolors="k", zorder=3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("COMAC per point over the pairs (five lowest labelled)")
    fig.colorbar(sc, ax=ax, fraction=0.046, pad=0.04, label="COMAC")
    worst = np.argsort(values)[: min(5, len(values))]
    place_labels(ax, xy[worst], [f"{labels[i]}\n{values[i]:.2f}" for i in worst], fontsize=7)
    save_figure(fig, path, **PLOT)
