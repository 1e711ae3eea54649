"""The component library: one TOML file per part family (size, mass, default model, equivalent
thickness with its standard deviation, the calibration runs behind it, and where the numbers come from).

The one search path (:func:`search_path`): a board looks for a family first in the folders a command
names with ``--library DIR`` (:func:`chosen`), then in a ``library/`` folder next to its board.toml,
then in the folders named in the PCBDYN_LIBRARY path variable (``os.pathsep``-separated), then in the
library shipped with pcbdyn (:func:`shipped_library`: the repository's top-level ``library/``, installed
as ``pcbdyn/library/`` package data, so a plain ``pip install`` has it).
"""

from __future__ import annotations

import os
import re
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from ..inputs import MAX_NAME, MAX_TEXT, Reader, read_toml
from ..units import shown

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
    """The folder of part families shipped with pcbdyn: ``pcbdyn/library/`` of an installed package (setup.py
    maps the repository's ``library/`` there), else, in a source tree or an editable install, the
    repository's ``library/``."""
    package = Path(__file__).resolve().parents[1]
    installed = package / "library"
    return installed if installed.is_dir() else package.parent / "library"


def available(board_dir: Path | None = None) -> list[str]:
    names = set()
    for d in search_path(board_dir):
        if d.is_dir():
            names.update(p.stem for p in d.glob("*.toml") if not p.name.startswith("."))
    return sorted(names)


def read_package(path: Path) -> Package:
    """Read one library file (table ``[package]``); a LibraryError names the file, the field and the fix."""
    path = Path(path)
    data = read_toml(path, LibraryError)[1]
    r = Reader(path, LibraryError)
    if not isinstance(data.get("package"), dict):
        r.fail("package", "missing; the file needs a [package] table with size, height, mass, default_model and "
                          "equivalent_thickness")
    p = r.table(data["package"], "package", PACKAGE_KEYS, required=PACKAGE_KEYS[1:6])
    size = p["size"]
    if not (isinstance(size, list) and len(size) == 2):
        r.fail("package.size", f"must be two lengths, e.g. [\"40 mm\", \"40 mm\"], got {shown(size)}")
    model = r.choice(p["default_model"], "package.default_model", MODELS, "part model")
    return Package(
        name=r.text(p["name"], "package.name", MAX_NAME) if "name" in p else path.stem,
        size=tuple(r.q(s, "mm", f"package.size[{i}]", positive=True) for i, s in enumerate(size)),
        height=r.q(p["height"], "mm", "package.height", nonneg=True),
        mass=r.q(p["mass"], "g", "package.mass", positive=True),
        default_model=model,
        equivalent_thickness=r.q(p["equivalent_thickness"], "mm", "package.equivalent_thickness", positive=True),
        provenance=r.text(p.get("provenance", ""), "package.provenance", 20 * MAX_TEXT, lines=True),
        path=path,
        steinberg_c=_steinberg_c(r, p),
        equivalent_thickness_std=r.q(p["equivalent_thickness_std"], "mm", "package.equivalent_thickness_std",
                                     nonneg=True) if "equivalent_thickness_std" in p else None,
    )


#: the fields of ``[package]``
PACKAGE_KEYS = ["name", "size", "height", "mass", "default_model", "equivalent_thickness", "provenance", "steinberg_c",
                "equivalent_thickness_std"]


def _steinberg_c(r, p: dict) -> float | None:
    if "steinberg_c" not in p:
        return None
    c = r.number(p["steinberg_c"], "package.steinberg_c")
    if not 0 < c <= 10:
        r.fail("package.steinberg_c", f"must be a number above 0 (Steinberg's package constant, e.g. 1.0 for a "
                                      f"standard DIP, 1.75 for a BGA), got {c!r}")
    return c


def check_family(name) -> str | None:
    """Why ``name`` cannot name a part family (None when it can): a family is a file ``<name>.toml`` in a
    library folder, so its name is a plain file name of letters, digits and ``_-+.``."""
    if not isinstance(name, str) or not _FAMILY.fullmatch(name):
        return (f"{shown(name)} is not a family name: use at most {MAX_NAME} letters, digits and _ - + . (not "
                "starting with a dot), e.g. \"QFP44\"")
    return None


_FAMILY = re.compile(rf"[A-Za-z0-9_+\-][A-Za-z0-9_+.\-]{{0,{MAX_NAME - 1}}}")


def locate(name: str, board_dir: Path | None = None) -> Path | None:
    """The file of family ``name`` in the first library folder that has it, or None; a LibraryError
    for a name that is no family name (:func:`check_family`)."""
    if (why := check_family(name)) is not None:
        raise LibraryError(why)
    for d in search_path(board_dir):
        f = d / f"{name}.toml"
        if f.is_file():
            return f
    return None


def find_package(name: str, board_dir: Path | None = None) -> Package | None:
    """The family ``name`` from the first library folder that has it, or None."""
    f = locate(name, board_dir)
    return None if f is None else read_package(f)
