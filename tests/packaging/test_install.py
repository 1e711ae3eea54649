"""A plain (non-editable) ``pip install`` carries what pcbdyn needs at run time: the component
library (``library/`` at the top of the repository) is package data, so the bundled example builds
from an installed copy, far from the source tree; and the library search order is the board's folder,
PCBDYN_LIBRARY, then the shipped library."""

import importlib.metadata
import importlib.util
import json
import os
import shutil
import site
import subprocess
import sys
from pathlib import Path

import pytest

from pcbdyn.components.library import find_package, search_path, shipped_library

ROOT = Path(__file__).resolve().parents[2]


def _venv_reusing_this_environment(folder: Path) -> Path:
    """A fresh venv (no pip of its own) that sees this environment's installed packages after its
    own: a .pth line per site folder (plain lines: the editable-install hooks there do not run)."""
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder)], check=True)
    py = folder / "bin" / "python"
    purelib = subprocess.check_output([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                                      text=True).strip()
    Path(purelib, "_reuse_outer.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    return py


def _can_build_wheels_here() -> bool:
    """setuptools can build a wheel without the ``wheel`` package from 70.1 (the test extra asks for it)."""
    try:
        major, minor = (int(v) for v in importlib.metadata.version("setuptools").split(".")[:2])
    except (importlib.metadata.PackageNotFoundError, ValueError):
        return False
    return (major, minor) >= (70, 1) or importlib.util.find_spec("wheel") is not None


def _clean_env() -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PCBDYN_LIBRARY", "PYTHONHOME")}
    env["OPENBLAS_NUM_THREADS"] = "1"
    return env


def test_a_plain_install_in_a_fresh_venv_builds_the_example(tmp_path):
    src = tmp_path / "src"  # what a source distribution holds: no tests, no examples
    for folder in ("pcbdyn", "library"):
        shutil.copytree(ROOT / folder, src / folder, ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "setup.py", "README.md"):
        shutil.copy(ROOT / name, src / name)
    py = _venv_reusing_this_environment(tmp_path / "venv")
    isolation = ["--no-build-isolation"] if _can_build_wheels_here() else []  # else pip fetches setuptools
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "-q", "--no-deps", *isolation,
                    str(src)], check=True, env=_clean_env())
    shutil.rmtree(src)  # nothing may still point into the source tree

    example = tmp_path / "card"
    shutil.copytree(ROOT / "examples" / "six_part_card", example)
    where = subprocess.run([py, "-c", "import pcbdyn; from pcbdyn.components.library import shipped_library as s; "
                                      "print(pcbdyn.__file__); print(s())"], cwd=tmp_path, env=_clean_env(),
                           capture_output=True, text=True, check=True).stdout.split("\n")
    assert Path(where[0]).is_relative_to(tmp_path / "venv"), where
    installed = Path(where[1])
    assert installed == Path(where[0]).parent / "library" and installed.is_relative_to(tmp_path / "venv"), where
    assert sorted(p.name for p in installed.glob("*.toml")) == sorted(p.name for p in (ROOT / "library").glob("*.toml"))
    res = subprocess.run([tmp_path / "venv" / "bin" / "pcbdyn", "build", str(example / "board.toml"), "--no-pictures",
                          "--json", str(tmp_path / "modes.json"), "--out", str(tmp_path / "out"), "--html"],
                         cwd=tmp_path, env=_clean_env(), capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    modes = json.loads((tmp_path / "modes.json").read_text())["modes"]
    assert len(modes) == 7 and modes[0]["frequency_hz"] == pytest.approx(197.9, abs=0.1)
    page = (tmp_path / "out" / "report.html").read_text()
    assert "pcbdyn: animated 3-D mode views" in page and "plotly.js v" in page  # view3d.js ships as package data


def test_the_board_folder_then_pcbdyn_library_then_the_shipped_library(tmp_path, monkeypatch):
    shipped = shipped_library()
    assert shipped == ROOT / "library" and not (ROOT / "pcbdyn" / "library").exists()  # the source tree's
    assert {"PGA", "JLCC", "CQFP"} <= {p.stem for p in shipped.glob("*.toml")}
    board_dir, env_dir = tmp_path / "board", tmp_path / "env"
    for folder, mass in ((board_dir / "library", "1 g"), (env_dir, "2 g")):
        folder.mkdir(parents=True)
        text = (shipped / "PGA.toml").read_text().replace('mass = "14 g"', f'mass = "{mass}"')
        (folder / "PGA.toml").write_text(text)
    monkeypatch.setenv("PCBDYN_LIBRARY", str(env_dir))
    assert search_path(board_dir) == [board_dir / "library", env_dir, shipped]
    assert find_package("PGA", board_dir).mass == pytest.approx(1e-3)
    assert find_package("PGA", tmp_path).mass == pytest.approx(2e-3)
    monkeypatch.delenv("PCBDYN_LIBRARY")
    assert find_package("PGA", tmp_path).mass == pytest.approx(14e-3)
