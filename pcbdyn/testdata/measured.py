"""The measured modes of a structure's test configurations, read from the files a user names: UFF
files (dataset 55 shapes) per configuration, or a CSV table of frequencies."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .data import Modes, TestDataError
from .uff import read_uff

#: configuration names of a frequency table that mean the base configuration
BASE_NAMES = ("base", "c1", "")


def read_modes(path) -> Modes:
    """The measured modes of a UFF file; a clear error when there are none."""
    data = read_uff(path)
    if data.modes is None or data.modes.n_modes == 0:
        what = " (it holds FRFs only: identify modes from them first)" if data.frfs is not None else ""
        raise TestDataError(f"{path}: no mode shapes (UFF dataset 55) in the file{what}; export the test's mode "
                            "shapes as dataset 55, or write a test with 'pcbdyn simulate-test'")
    return data.modes


def _configuration(structure, name, source) -> str:
    if name not in structure.configuration_names():
        known = ", ".join(structure.configuration_names()) or "none"
        raise TestDataError(f"{source}: configuration '{name}' is not in [[configurations]] of "
                            f"{structure.path.name} (known: {known})")
    return name


def read_tests(structure, base, extras=()) -> list:
    """[(configuration name or None, Modes)] of the base test file ``base`` and of ``extras``
    [(configuration name, file)] of ``structure``'s perturbed configurations."""
    data = [(None, read_modes(base))]
    for name, path in extras:
        data.append((_configuration(structure, name, f"{name}={path}"), read_modes(path)))
    return data


def read_frequency_table(path, structure) -> list:
    """[(configuration or None, Modes of frequencies only)] from a CSV of measured frequencies with
    columns configuration, mode, frequency_hz (configuration base or c1: the base configuration);
    each mode pairs with the model's elastic mode of its number."""
    import pandas as pd

    path = Path(path)
    try:
        df = pd.read_csv(path, comment="#")
    except (ValueError, OSError, UnicodeDecodeError) as exc:
        raise TestDataError(f"{path.name}: cannot be read as CSV ({exc})") from None
    need = {"configuration", "mode", "frequency_hz"}
    if not need <= set(df.columns):
        raise TestDataError(f"{path.name}: needs columns {sorted(need)}, found {list(df.columns)}")
    out = []
    for name, g in df.groupby("configuration", sort=False):
        cfg = None if str(name) in BASE_NAMES else _configuration(structure, str(name), path.name)
        try:
            f, n = g["frequency_hz"].to_numpy(float), g["mode"].to_numpy(float)
        except ValueError as exc:
            raise TestDataError(f"{path.name}: configuration {name}: {exc}; give numbers") from None
        if np.any(n != np.round(n)) or np.any(n < 1):
            raise TestDataError(f"{path.name}: configuration {name}: mode numbers must be whole numbers >= 1")
        out.append((cfg, Modes.frequencies_only(f, n.astype(int))))
    return out
