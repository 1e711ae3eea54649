"""Mesh and mode shapes as a VTU file for ParaView (pyvista), one point array per mode."""

from __future__ import annotations

import numpy as np

from .files import atomic_path


def shell_grid(model):
    """A pyvista UnstructuredGrid of the model's quad4/tri3 cells, with a cell array 'set' (index
    into the sorted shell set names, listed in field data 'set_names')."""
    import pyvista as pv

    cells, types, set_id, names = [], [], [], []
    for name, es in model.sets.items():
        if es.etype not in ("quad4", "tri3"):
            continue
        n = es.conn.shape[1]
        cells.append(np.hstack([np.full((len(es.conn), 1), n), es.conn]).ravel())
        types.append(np.full(len(es.conn), pv.CellType.QUAD if n == 4 else pv.CellType.TRIANGLE, dtype=np.uint8))
        set_id.append(np.full(len(es.conn), len(names)))
        names.append(name)
    grid = pv.UnstructuredGrid(np.concatenate(cells), np.concatenate(types), model.nodes)
    grid.cell_data["set"] = np.concatenate(set_id)
    grid.field_data["set_names"] = np.array(names)
    return grid


def write_modes_vtu(path, model, frequencies, shapes) -> None:
    """Write the mesh with arrays mode_<k> (displacement vectors, max |w| = 1) and field data
    'frequency_hz'."""
    grid = shell_grid(model)
    for j, f in enumerate(frequencies):
        u = shapes[:, j].reshape(-1, 6)[:, :3]
        scale = np.max(np.abs(u[:, 2])) or 1.0
        grid.point_data[f"mode_{j + 1}"] = u / scale
    grid.field_data["frequency_hz"] = np.asarray(frequencies, dtype=float)
    with atomic_path(path) as tmp:
        grid.save(str(tmp))
