"""Structured meshes of a rectangle in the z = 0 plane (verification plates, simple panels)."""

from __future__ import annotations

import numpy as np

from .model import ModelError


def rectangle(a: float, b: float, nx: int, ny: int, kind: str = "quad4", origin=(0.0, 0.0, 0.0)):
    """Nodes (n, 3) and cells of an a x b rectangle on a grid of nx x ny equal cells.

    Nodes are numbered row by row, node (i, j) at x = i a / nx, y = j b / ny having index
    j (nx + 1) + i. Cells run counter-clockwise (normal +z). ``kind`` 'quad4' gives nx ny
    quads; 'tri3' splits every grid cell along its (i, j)-(i+1, j+1) diagonal into two triangles.
    """
    if not (a > 0 and b > 0):
        raise ModelError(f"rectangle needs side lengths a > 0 and b > 0, got a={a}, b={b}")
    if int(nx) != nx or int(ny) != ny or nx < 1 or ny < 1:
        raise ModelError(f"rectangle needs integer divisions nx, ny >= 1, got nx={nx}, ny={ny}")
    nx, ny = int(nx), int(ny)
    x, y = np.meshgrid(np.linspace(0.0, a, nx + 1), np.linspace(0.0, b, ny + 1))
    nodes = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]) + np.asarray(origin, dtype=float)
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    n0 = (j * (nx + 1) + i).ravel()
    n1, n2, n3 = n0 + 1, n0 + nx + 2, n0 + nx + 1
    if kind == "quad4":
        conn = np.column_stack([n0, n1, n2, n3])
    elif kind == "tri3":
        conn = np.vstack([np.column_stack([n0, n1, n2]), np.column_stack([n0, n2, n3])])
    else:
        raise ModelError(f"rectangle kind must be 'quad4' or 'tri3', got '{kind}'")
    return nodes, conn


def nodes_where(nodes, x=None, y=None, z=None, tol: float = 1e-9) -> np.ndarray:
    """Indices of the nodes whose given coordinates equal the given values (within ``tol`` times
    the model size), e.g. ``nodes_where(nodes, x=0.0)`` for the edge x = 0."""
    nodes = np.asarray(nodes, dtype=float)
    scale = float(np.ptp(nodes, axis=0).max()) if nodes.size else 0.0
    scale = scale if scale > 0 else 1.0
    keep = np.ones(nodes.shape[0], dtype=bool)
    for axis, value in enumerate((x, y, z)):
        if value is not None:
            keep &= np.abs(nodes[:, axis] - value) <= tol * scale
    return np.flatnonzero(keep)


def rectangle_edges(nodes, a: float, b: float, origin=(0.0, 0.0, 0.0), tol: float = 1e-9) -> dict:
    """The four edges of a rectangle mesh: {'x0', 'x1', 'y0', 'y1'} -> node indices, where 'x0' is
    the edge x = origin_x and 'x1' the edge x = origin_x + a (likewise y)."""
    ox, oy, _ = origin
    return {
        "x0": nodes_where(nodes, x=ox, tol=tol),
        "x1": nodes_where(nodes, x=ox + a, tol=tol),
        "y0": nodes_where(nodes, y=oy, tol=tol),
        "y1": nodes_where(nodes, y=oy + b, tol=tol),
    }
