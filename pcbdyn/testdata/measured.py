"""The measured modes of a structure's test configurations, read from the files a user names: UFF
files (dataset 55 shapes) per configuration, or a CSV table of frequencies."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .data import FILE_FLOOR_HZ, MeasuredModes, TestDataError, check_frequencies
from .uff import read_uff

#: configuration names of a frequency table that mean the base configuration
BASE_NAMES = ("base", "c1", "")


def read_modes(path) -> MeasuredModes:
    """The measured modes of a UFF file; a clear error when there are none."""
    return read_test(path).modes


def read_test(path):
    """What a UFF test file holds (:class:`.data.TestData`: its modes, points and wireframe), with a clear
    error when it has no modes."""
    from ..domain import MAX_MODES

    data = read_uff(path)
    if data.modes is not None and data.modes.n_modes > MAX_MODES:
        raise TestDataError(f"{path}: {data.modes.n_modes} modes, more than the {MAX_MODES} pcbdyn pairs with a model; "
                            "keep the measured modes of interest")
    if data.modes is None or data.modes.n_modes == 0:
        what = " (it holds FRFs only: identify modes from them first)" if data.frfs is not None else ""
        raise TestDataError(f"{path}: no mode shapes (UFF dataset 55) in the file{what}; export the test's mode "
                            "shapes as dataset 55, or write a test with 'pcbdyn simulate-test'")
    return data


def read_geometry(path):
    """The measurement points of a points CSV (point, x, y, z with units in the header) or of the geometry
    of a UFF file (datasets 15, 2411), for test files that carry none."""
    from .csvio import read_points_csv

    path = Path(path)
    if path.suffix.lower() == ".csv":
        return read_points_csv(path)[0]
    points = read_uff(path).points
    if not len(points):
        raise TestDataError(f"{path}: no geometry (UFF datasets 15 or 2411); give a points CSV (point, x [mm], "
                            "y [mm], z [mm]) or a UFF file with the points")
    return points


def _configuration(structure, name, source) -> str:
    if name not in structure.configuration_names():
        known = ", ".join(structure.configuration_names()) or "none"
        raise TestDataError(f"{source}: configuration '{name}' is not in [[configurations]] of "
                            f"{structure.path.name} (known: {known})")
    return name


def read_tests(structure, base, extras=()) -> list:
    """[(configuration name or None, MeasuredModes)] of the base test file ``base`` and of ``extras``
    [(configuration name, file)] of ``structure``'s perturbed configurations."""
    data = [(None, read_modes(base))]
    for name, path in extras:
        data.append((_configuration(structure, name, f"{name}={path}"), read_modes(path)))
    return data


def read_frequency_table(path, structure) -> list:
    """[(configuration or None, MeasuredModes of frequencies only)] from a CSV of measured frequencies with
    columns configuration, mode, frequency_hz (configuration base or c1: the base configuration);
    each mode pairs with the model's elastic mode of its number."""
    from ..domain import MAX_MODES
    from ..inputs import read_csv
    from .csvio import numbers

    path = Path(path)
    df = read_csv(path, TestDataError, dtype={"configuration": str}, keep_default_na=False)
    need = {"configuration", "mode", "frequency_hz"}
    if not need <= set(df.columns):
        raise TestDataError(f"{path.name}: needs columns {sorted(need)}, found {[str(c)[:40] for c in df.columns][:10]}")
    if df.empty:
        raise TestDataError(f"{path.name}: no data rows below the header; give one row per measured mode")
    f, n = numbers(path.name, df, "frequency_hz"), numbers(path.name, df, "mode", whole=True)
    out = []
    for name, rows in df.groupby("configuration", sort=False).indices.items():
        cfg = None if str(name) in BASE_NAMES else _configuration(structure, str(name), path.name)
        fc, nc = f[rows], n[rows]
        if np.any(nc < 1) or np.any(nc > MAX_MODES):
            raise TestDataError(f"{path.name}: configuration {name}: mode numbers must be whole numbers from 1 to "
                                f"{MAX_MODES}")
        if np.unique(nc).size < nc.size:
            raise TestDataError(f"{path.name}: configuration {name}: a mode number is given twice; give each mode once")
        check_frequencies(fc, f"{path.name}: configuration {name}", nc, floor=FILE_FLOOR_HZ)
        out.append((cfg, MeasuredModes.frequencies_only(fc, nc)))
    return out
