"""The component library: one TOML file per part family (size, mass, default model, equivalent
thickness with its standard deviation, the calibration runs behind it, and where the numbers come from).

The one search path (:func:`search_path`): a board looks for a family first in the folders a command
names with ``--library DIR`` (:func:`chosen`), then in a ``library/`` folder next to its board.toml,
then in the folders named in the PCBDYN_LIBRARY path variable (``os.pathsep``-separated), then in the
library shipped inside the package (``pcbdyn/library/``, package data, so a plain ``pip install`` has
it).
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..inputs import read_toml
from ..units import UnitError, to_si

MODELS = ("lumped", "spread", "smeared_local", "equivalent_thickness")


class LibraryError(ValueError):
    """A library file that cannot be read, with the file, the field and the fix."""


@dataclass(frozen=True)
class Package:
    """One part family: footprint ``size`` (x, y) [m], body ``height`` [m], ``mass`` [kg],
    ``default_model`` (one of :data:`MODELS`), ``equivalent_thickness`` [m] of the board region under
    the part (thesis section 7.2.3), and free-text ``provenance``. Optional: ``steinberg_c``, the
    package constant of Steinberg's allowable board displacement (lead wires and solder joints;
    used by ``pcbdyn vibe``), None when the entry does not give one; ``equivalent_thickness_std``
    [m], the standard deviation of a calibrated equivalent thickness (``pcbdyn calibrate``), None
    for a value nobody measured."""

    name: str
    size: tuple
    height: float
    mass: float
    default_model: str
    equivalent_thickness: float
    provenance: str
    path: Path
    steinberg_c: float | None = None
    equivalent_thickness_std: float | None = None


#: folders named on the command line (``--library DIR``), searched first; set with :func:`chosen`
_CHOSEN: list = []


@contextmanager
def chosen(dirs):
    """Search the folders ``dirs`` first while the block runs (a command's ``--library DIR``)."""
    saved = list(_CHOSEN)
    _CHOSEN[:0] = [Path(d) for d in dirs]
    try:
        yield
    finally:
        _CHOSEN[:] = saved


def search_path(board_dir: Path | None = None) -> list[Path]:
    """Folders searched for ``<package>.toml``, first match wins (see the module docstring)."""
    dirs = list(_CHOSEN)
    if board_dir is not None:
        dirs.append(Path(board_dir) / "library")
    env = os.environ.get("PCBDYN_LIBRARY")
    if env:
        dirs.extend(Path(p) for p in env.split(os.pathsep) if p)
    dirs.append(shipped_library())
    return dirs


def shipped_library() -> Path:
    """The folder of part families installed with pcbdyn (package data)."""
    return Path(str(resources.files("pcbdyn") / "library"))


def available(board_dir: Path | None = None) -> list[str]:
    names = set()
    for d in search_path(board_dir):
        if d.is_dir():
            names.update(p.stem for p in d.glob("*.toml") if not p.name.startswith("."))
    return sorted(names)


def read_package(path: Path) -> Package:
    """Read one library file (table ``[package]``)."""
    path = Path(path)
    data = read_toml(path, LibraryError)[1]
    p = data.get("package")
    if not isinstance(p, dict):
        raise LibraryError(f"{path}: needs a [package] table with size, height, mass, default_model, equivalent_thickness")
    where = f"{path.name}: package"
    try:
        for key in ("size", "height", "mass", "default_model", "equivalent_thickness"):
            if key not in p:
                raise LibraryError(f"{path}: package.{key} is missing; add it")
        size = p["size"]
        if not (isinstance(size, list) and len(size) == 2):
            raise LibraryError(f"{path}: package.size must be two lengths, e.g. [\"40 mm\", \"40 mm\"]")
        model = p["default_model"]
        if model not in MODELS:
            raise LibraryError(f"{path}: package.default_model '{model}' is not one of {', '.join(MODELS)}")
        return Package(
            name=str(p.get("name", path.stem)),
            size=tuple(to_si(s, "mm", f"{where}.size") for s in size),
            height=to_si(p["height"], "mm", f"{where}.height"),
            mass=to_si(p["mass"], "g", f"{where}.mass"),
            default_model=model,
            equivalent_thickness=to_si(p["equivalent_thickness"], "mm", f"{where}.equivalent_thickness"),
            provenance=str(p.get("provenance", "")),
            path=path,
            steinberg_c=_steinberg_c(path, p),
            equivalent_thickness_std=_std(path, p, where),
        )
    except UnitError as exc:
        raise LibraryError(str(exc)) from None


def _std(path: Path, p: dict, where: str) -> float | None:
    if "equivalent_thickness_std" not in p:
        return None
    sd = to_si(p["equivalent_thickness_std"], "mm", f"{where}.equivalent_thickness_std")
    if not sd >= 0:
        raise LibraryError(f"{path}: package.equivalent_thickness_std must not be negative, got "
                           f"{p['equivalent_thickness_std']!r}")
    return sd


def _steinberg_c(path: Path, p: dict) -> float | None:
    c = p.get("steinberg_c")
    if c is None:
        return None
    if isinstance(c, bool) or not isinstance(c, (int, float)) or not c > 0:
        raise LibraryError(f"{path}: package.steinberg_c must be a positive number (Steinberg's package constant, "
                           f"e.g. 1.0 for a standard DIP, 1.75 for a BGA), got {c!r}")
    return float(c)


def locate(name: str, board_dir: Path | None = None) -> Path | None:
    """The file of family ``name`` in the first library folder that has it, or None."""
    for d in search_path(board_dir):
        f = d / f"{name}.toml"
        if f.is_file():
            return f
    return None


def find_package(name: str, board_dir: Path | None = None) -> Package | None:
    """The family ``name`` from the first library folder that has it, or None."""
    f = locate(name, board_dir)
    return None if f is None else read_package(f)
