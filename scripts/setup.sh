#!/usr/bin/env bash
# Install what pcbdyn needs on a fresh Debian 12 machine: the shared libraries gmsh and VTK load,
# SuiteSparse for CHOLMOD, a threaded OpenBLAS, Chromium and its driver (the tests open the HTML
# reports in a real headless browser), CalculiX (calculix-ccx: the box tests check pcbdyn's box
# against another FE code), then a virtual environment with the package.
# Idempotent: a second run only checks.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
pkgs="libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1 libgomp1 libegl1 libgl1-mesa-dri libosmesa6 libsuitesparse-dev libopenblas0-pthread gcc python3-dev chromium chromium-driver calculix-ccx"
missing=""
for p in $pkgs; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  sudo=""; [ "$(id -u)" = 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends $missing
fi
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
fi
"$here/.venv/bin/python" -m pip install -q --upgrade pip
"$here/.venv/bin/python" -m pip install -q -e "$here[test]"
# pyNastran (reads the exported Nastran decks back in the tests) pins numpy<2, which the main
# environment cannot share: it gets a virtual environment of its own.
if [ ! -x "$here/.venv-nastran/bin/python" ]; then
  python3 -m venv "$here/.venv-nastran"
fi
"$here/.venv-nastran/bin/python" -m pip install -q "numpy<2" "pyNastran==1.4.1"
