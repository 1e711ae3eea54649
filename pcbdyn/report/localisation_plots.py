"""Pictures of error localisation: indicator maps on the board, the epsilon-condition-number
curve used to choose the rank (thesis Fig. 5.13a), the selection order and descending ratios
(Figs. 5.5, 5.6) with the parameters named, and success-ratio charts (Fig. 5.14)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .files import save_figure


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _triangles(cells):
    cells = np.asarray(cells, int)
    if cells.shape[1] == 3:
        return cells
    return np.vstack([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])


def node_map(ax, xy, cells, values, title: str = "", cmap: str = "viridis"):
    """Node values over the mesh (quads split in two triangles, Gouraud shading); ``cells`` None
    triangulates the points (Delaunay), e.g. for test points. xy in m, drawn in mm. Returns the
    mappable for a colour bar."""
    import matplotlib.tri as mtri

    xy = np.asarray(xy, float)[:, :2] * 1e3
    tri = mtri.Triangulation(xy[:, 0], xy[:, 1], None if cells is None else _triangles(cells))
    m = ax.tripcolor(tri, np.asarray(values, float), shading="gouraud", cmap=cmap)
    ax.triplot(tri, color="0.6", lw=0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title)
    return m


def element_map(ax, xy, cells, values, title: str = "", cmap: str = "viridis"):
    """One value per cell (e.g. a localised thickness change) as filled polygons."""
    from matplotlib.collections import PolyCollection

    xy = np.asarray(xy, float)[:, :2] * 1e3
    pc = PolyCollection([xy[c] for c in np.asarray(cells, int)], array=np.asarray(values, float), cmap=cmap,
                        edgecolors="0.5", linewidths=0.3)
    ax.add_collection(pc)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title)
    return pc


def save_map(path, xy, cells, values, title: str, per: str = "node") -> Path:
    """Write one map (``per`` 'node' or 'element') with a colour bar to ``path`` (PNG); points (k, 3) of a
    structure in 3-D (a box) as a 3-D map of the values at the points."""
    plt = _pyplot()
    if np.shape(xy)[1] == 3:
        from .pictures3d import point_map_3d

        fig = plt.figure(figsize=(6.5, 5.5))
        point_map_3d(fig, 111, xy, values, "", title=title)
        return save_figure(fig, path, dpi=120)
    fig, ax = plt.subplots(figsize=(5.5, 5))
    m = (node_map if per == "node" else element_map)(ax, xy, cells, values, title)
    fig.colorbar(m, ax=ax)
    fig.tight_layout()
    return save_figure(fig, path, dpi=120)


def condition_curve_plot(ax, curve, rank: int | None = None):
    """Trial epsilon-condition number sigma_1 / sigma_r vs r (thesis eq. 4.21, Fig. 5.13a),
    with the chosen rank marked."""
    c = np.asarray(curve, float)
    r = np.arange(1, c.size + 1)
    ok = np.isfinite(c)
    ax.semilogy(r[ok], c[ok], "o-", ms=3)
    if rank:
        ax.axvline(rank, color="C3", ls="--", label=f"rank {rank}")
        ax.legend()
    ax.set_xlabel("trial rank r")
    ax.set_ylabel("k2(A) at rank r")
    ax.set_title("epsilon-condition number")


#: most parameters a panel of the localisation figure names (one row each)
NAMED = 15


def _named_bars(ax, values, labels, highlight=()):
    """Horizontal bars, one row per label from the top, the ``highlight`` rows coloured."""
    y = np.arange(len(labels))
    ax.barh(y, values, color=["C3" if k in highlight else "C0" for k in range(len(labels))])
    ax.set_yticks(y, labels, fontsize=8)
    ax.set_ylim(len(labels) - 0.5, -0.5)


def localisation_figure(path, subset, names) -> Path:
    """Three panels of one localisation (as thesis Fig. 5.13), parameters by name: the condition curve,
    the parameters in their selection order with their residue descending ratios (Figs. 5.5-5.6, eq.
    5.60; those retained in red) and the subset solution (the largest changes, the selected in red)."""
    plt = _pyplot()
    fig, axs = plt.subplots(1, 3, figsize=(14, 5), gridspec_kw={"width_ratios": [1.1, 1, 1]})
    condition_curve_plot(axs[0], subset.condition_curve, subset.rank)
    ratio = np.asarray(subset.descending_ratio, float)[:NAMED]
    order = np.asarray(subset.order, int)[: ratio.size]
    _named_bars(axs[1], ratio, [f"{k + 1}. {names[i]}" for k, i in enumerate(order)],
                highlight=range(len(subset.retained)))
    axs[1].set_xlabel("residue descending ratio dRr [%]")
    axs[1].set_title(f"selection order ({len(order)} of {len(names)}; retained in red)")
    x = np.asarray(subset.x, float)
    chosen = [int(i) for i in subset.selected]
    rows = (chosen + [int(i) for i in np.argsort(-np.abs(x), kind="stable") if i not in chosen])[:max(NAMED,
                                                                                                   len(chosen))]
    _named_bars(axs[2], x[rows], [names[i] for i in rows], highlight=range(len(chosen)))
    axs[2].axvline(0.0, color="0.3", lw=0.8)
    axs[2].set_xlabel("relative change")
    axs[2].set_title(f"{subset.method} solution (selected in red)")
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)


def success_ratio_figure(path, summary, equations: str | None = None) -> Path:
    """Mean success ratio (solid) and mean +- one standard deviation (dashed, clipped to
    0-100 %) vs noise level, one panel per method (thesis Fig. 5.14). ``summary`` is the
    DataFrame of :func:`pcbdyn.updating.study.summarise`; with several equation types, each
    gets its own line (or pick one with ``equations``)."""
    plt = _pyplot()
    s = summary if equations is None else summary[summary["equations"] == equations]
    methods = list(dict.fromkeys(s["method"]))
    fig, axs = plt.subplots(1, len(methods), figsize=(4.2 * len(methods), 3.8), squeeze=False)
    for ax, method in zip(axs[0], methods):
        for k, (kind, g) in enumerate(s[s["method"] == method].groupby("equations")):
            g = g.sort_values("level_pct")
            lv, mean, std = g["level_pct"], g["mean"], g["std"]
            ax.plot(lv, mean, "-", color=f"C{k}", label=kind)
            ax.plot(lv, np.clip(mean + std, 0, 100), "--", color=f"C{k}", lw=0.8)
            ax.plot(lv, np.clip(mean - std, 0, 100), "--", color=f"C{k}", lw=0.8)
        ax.set_ylim(0, 105)
        ax.set_xlabel("measurement error level [%]")
        ax.set_ylabel("success ratio [%]")
        ax.set_title(method)
        ax.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
