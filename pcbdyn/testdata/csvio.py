"""CSV in and out: points (with optional directions), mode frequencies and mode shapes.

Headers carry units in brackets, e.g. ``point,x [mm],y [mm],z [mm],dir``; lengths are converted to
metres on reading and written in metres. ``dir`` holds +x, -y, z, ... (default z: a vibrometer).
Frequencies: ``mode,frequency [Hz],damping ratio,mpc``. Shapes: ``point,x [m],y [m],z [m],dx,dy,dz,
mode 1,...``: one row per measured DOF.
"""

from __future__ import annotations

import io
import os
import re

import numpy as np

from ..units import LENGTHS, shown
from .data import FILE_FLOOR_HZ, Dofs, MeasuredModes, Points, TestDataError, check_frequencies
from .uff_write import _atomic

_HEAD = re.compile(r"^\s*([A-Za-z][A-Za-z0-9 ]*?)\s*(?:[\[(]\s*([^\])]*)\s*[\])]|_(mm|cm|m|um|in))?\s*$")


def _table(path):
    from ..inputs import read_csv

    path = os.fspath(path)
    df = read_csv(path, TestDataError, skipinitialspace=True)
    if df.empty:
        raise TestDataError(f"{path}: no data rows below the header")
    cols = {}
    for c in df.columns:
        m = _HEAD.match(str(c)[:100])
        if not m:
            raise TestDataError(f"{path}: column {shown(str(c))} is not 'name' or 'name [unit]'")
        name = m.group(1).strip().lower()
        if name in cols:
            raise TestDataError(f"{path}: two columns are called '{name}'; keep one")
        cols[name] = (c, m.group(2) or m.group(3))
    return df, cols


def numbers(path, df, col, whole: bool = False) -> np.ndarray:
    """Column ``col`` of ``df`` as finite floats (``whole``: whole numbers as int64); a TestDataError names
    the file, the column and the first row that is not one."""
    import pandas as pd

    v = pd.to_numeric(df[col], errors="coerce").to_numpy(dtype=float)
    bad = ~np.isfinite(v) | ((v != np.round(v)) | (np.abs(v) > 2**53) if whole else False)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise TestDataError(f"{path}: data row {i + 1}: column '{col}' holds {shown(str(df[col].iloc[i]))}, not a "
                            f"{'whole number' if whole else 'finite number'}; give one in every row")
    return v.astype(np.int64) if whole else v


def _length_col(path, df, cols, name, unit, required=True):
    if name not in cols:
        if required:
            raise TestDataError(f"{path}: no column '{name}' (write it as '{name} [mm]' or '{name} [m]')")
        return np.zeros(len(df))
    col, u = cols[name]
    u = u or unit
    if u is None:
        raise TestDataError(f"{path}: column '{col}' has no unit; write it as '{name} [mm]' (or '{name} [m]')")
    if u not in LENGTHS:
        raise TestDataError(f"{path}: column '{col}': unit '{u}' is not one of {', '.join(LENGTHS)}")
    return numbers(path, df, col) * LENGTHS[u]


def read_points_csv(path, unit: str | None = None):
    """The measurement points and their measured directions, from a points CSV.

    Parameters
    ----------
    path : str or pathlib.Path
        A CSV with columns point, x, y, [z], [dir]; one row per point and direction (a point may
        appear on several rows with different directions, same coordinates).
    unit : str, optional
        The unit of coordinate columns written without one (``x [mm]`` states its own).

    Returns
    -------
    (Points, Dofs)
        Point ids and coordinates [m]; the measured DOFs (point id, unit direction).

    Examples
    --------
    >>> points, dofs = read_points_csv("examples/six_part_card/points.csv")
    >>> len(points.ids), len(dofs)
    (81, 81)
    """
    df, cols = _table(path)
    key = "point" if "point" in cols else "id" if "id" in cols else None
    if key is None:
        raise TestDataError(f"{path}: no 'point' column with the point ids")
    ids = numbers(path, df, cols[key][0], whole=True)
    xyz = np.column_stack([_length_col(path, df, cols, "x", unit), _length_col(path, df, cols, "y", unit),
                           _length_col(path, df, cols, "z", unit, required=False)])
    dirs = df[cols["dir"][0]].astype(str).tolist() if "dir" in cols else ["+z"] * len(df)
    uid, first = np.unique(ids, return_index=True)
    for i in range(len(ids)):
        j = first[np.searchsorted(uid, ids[i])]
        if not np.allclose(xyz[i], xyz[j]):
            raise TestDataError(f"{path}: point {ids[i]} is given with two different coordinates")
    try:
        dofs = Dofs.from_codes(ids, dirs)
    except TestDataError as exc:
        raise TestDataError(f"{path}: {exc}") from None
    seen = {}
    for i, key in enumerate(zip(ids.tolist(), map(tuple, np.round(dofs.directions, 12).tolist()))):
        if key in seen:
            raise TestDataError(f"{path}: data rows {seen[key] + 1} and {i + 1} give point {key[0]} in the same "
                                "direction; keep one of them")
        seen[key] = i
    return Points(uid, xyz[first]), dofs


def write_points_csv(path, points: Points, dofs: Dofs | None = None) -> None:
    """Points (and a direction per row when ``dofs`` is given) in metres."""
    if dofs is None:
        rows = np.arange(len(points))
        dirs = None
    else:
        rows = points.index(dofs.point_ids)
        dirs = [("+" if c > 0 else "-") + "xyz"[abs(c) - 1] for c in dofs.codes()]
    buf = io.StringIO()
    buf.write("point,x [m],y [m],z [m]" + (",dir\n" if dirs else "\n"))
    for k, r in enumerate(rows):
        x, y, z = (float(v) for v in points.xyz[r])
        buf.write(f"{points.ids[r]},{x!r},{y!r},{z!r}" + (f",{dirs[k]}\n" if dirs else "\n"))
    _write_text(path, buf.getvalue())


def _write_text(path, text):
    def write(tmp):
        with open(tmp, "w") as fh:
            fh.write(text)

    _atomic(path, write)


def write_modes_csv(freq_path, shapes_path, modes: MeasuredModes) -> None:
    """Frequencies (with damping and MPC) and shapes (one row per DOF) as two CSV files."""
    buf = io.StringIO()
    buf.write("mode,frequency [Hz],damping ratio,mpc\n")
    for j in range(modes.n_modes):
        buf.write(f"{j + 1},{float(modes.frequencies[j])!r},{float(modes.damping[j])!r},{float(modes.mpc[j])!r}\n")
    _write_text(freq_path, buf.getvalue())
    xyz = modes.dof_xyz()
    buf = io.StringIO()
    buf.write("point,x [m],y [m],z [m],dx,dy,dz," + ",".join(f"mode {j + 1}" for j in range(modes.n_modes)) + "\n")
    for i in range(len(modes.dofs)):
        vals = [*xyz[i], *modes.dofs.directions[i], *modes.shapes[i]]
        buf.write(f"{modes.dofs.point_ids[i]}," + ",".join(repr(float(v)) for v in vals) + "\n")
    _write_text(shapes_path, buf.getvalue())


def read_modes_csv(freq_path, shapes_path) -> MeasuredModes:
    """Measured modes from the two CSV files written by :func:`write_modes_csv` (or by hand: damping and mpc
    columns are optional; shape columns are named 'mode 1', 'mode 2', ...)."""
    df, cols = _table(freq_path)
    if "frequency" not in cols:
        raise TestDataError(f"{freq_path}: no 'frequency [Hz]' column")
    col, u = cols["frequency"]
    scale = {None: 1.0, "hz": 1.0, "khz": 1e3}.get((u or "hz").lower())
    if scale is None:
        raise TestDataError(f"{freq_path}: frequency unit '{u}' is not Hz or kHz")
    f = check_frequencies(numbers(freq_path, df, col) * scale, str(freq_path), floor=FILE_FLOOR_HZ)
    zeta = numbers(freq_path, df, cols["damping ratio"][0]) if "damping ratio" in cols else None
    mpc = numbers(freq_path, df, cols["mpc"][0]) if "mpc" in cols else None
    sf, scols = _table(shapes_path)
    for name in ("point", "dx", "dy", "dz"):
        if name not in scols:
            raise TestDataError(f"{shapes_path}: no column '{name}' (point, x [m], y [m], z [m], dx, dy, dz, mode 1, ...)")
    ids = numbers(shapes_path, sf, scols["point"][0], whole=True)
    xyz = np.column_stack([_length_col(shapes_path, sf, scols, a, "m") for a in "xyz"])
    d = np.column_stack([numbers(shapes_path, sf, scols[a][0]) for a in ("dx", "dy", "dz")])
    names = [f"mode {j + 1}" for j in range(f.size)]
    missing = [n for n in names if n not in scols]
    if missing:
        raise TestDataError(f"{shapes_path}: no columns {missing[:5]} for the {f.size} modes of {freq_path}")
    shapes = np.column_stack([numbers(shapes_path, sf, scols[n][0]) for n in names])
    uid, first = np.unique(ids, return_index=True)
    try:
        return MeasuredModes(Points(uid, xyz[first]), Dofs(ids, d), f, shapes, zeta, mpc)
    except TestDataError as exc:
        raise TestDataError(f"{freq_path}, {shapes_path}: {exc}") from None
