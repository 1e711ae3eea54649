"""What pyproject.toml cannot say: the component library at the top of the repository (``library/``) is
shipped inside the package as ``pcbdyn/library`` (package data, pyproject.toml), beside the packages under
pcbdyn/."""

from setuptools import find_namespace_packages, setup

setup(packages=find_namespace_packages(include=["pcbdyn", "pcbdyn.*"], exclude=["*.__pycache__"]) + ["pcbdyn.library"],
      package_dir={"pcbdyn.library": "library"})
