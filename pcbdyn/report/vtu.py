"""Mesh and mode shapes as a VTU file for ParaView (pyvista), one point array per mode."""

from __future__ import annotations

import numpy as np

from .files import atomic_path


#: the cells written, by element type
CELL_TYPES = {"quad4": "QUAD", "tri3": "TRIANGLE", "beam2": "LINE"}


def shell_grid(model):
    """A pyvista UnstructuredGrid of the model's quad4/tri3 cells and its beams (lines: ribs,
    stiffeners), with a cell array 'set' (index into the set names, listed in field data 'set_names')."""
    import pyvista as pv

    cells, types, set_id, names = [], [], [], []
    for name, es in model.sets.items():
        if es.etype not in CELL_TYPES:
            continue
        n = es.conn.shape[1]
        cells.append(np.hstack([np.full((len(es.conn), 1), n), es.conn]).ravel())
        types.append(np.full(len(es.conn), getattr(pv.CellType, CELL_TYPES[es.etype]), dtype=np.uint8))
        set_id.append(np.full(len(es.conn), len(names)))
        names.append(name)
    grid = pv.UnstructuredGrid(np.concatenate(cells), np.concatenate(types), model.nodes)
    grid.cell_data["set"] = np.concatenate(set_id)
    grid.field_data["set_names"] = np.array(names)
    return grid


def write_modes_vtu(path, model, frequencies, shapes) -> None:
    """Write the mesh with arrays mode_<k> (displacement vectors, max |w| = 1; max |u| = 1 for a
    structure in 3-D, :func:`pcbdyn.report.pictures.is_3d`, which also gets normal_<k>, the signed
    displacement along the outward normal, :func:`.rendering.normal_displacement`) and field data
    'frequency_hz'."""
    from .pictures import is_3d
    from .rendering import normal_displacement

    grid = shell_grid(model)
    flat = not is_3d(model)
    if not flat and len(frequencies):
        normal = normal_displacement(model, shapes)
        for j in range(len(frequencies)):
            grid.point_data[f"normal_{j + 1}"] = normal[:, j]
    for j, f in enumerate(frequencies):
        u = shapes[:, j].reshape(-1, 6)[:, :3]
        scale = (np.max(np.abs(u[:, 2])) if flat else np.max(np.linalg.norm(u, axis=1))) or 1.0
        grid.point_data[f"mode_{j + 1}"] = u / scale
    grid.field_data["frequency_hz"] = np.asarray(frequencies, dtype=float)
    with atomic_path(path) as tmp:
        grid.save(str(tmp))
