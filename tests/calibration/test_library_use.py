"""Using a calibrated library: ``--library DIR`` (and PCBDYN_LIBRARY) on a command that loads a board,
and ``pcbdyn build --uncertainty``, whose first-order frequency standard deviations must equal what
re-solving the board at the families' values +- their standard deviations gives."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from click.testing import CliRunner

from pcbdyn.board import load_board
from pcbdyn.cli import main
from pcbdyn.components.library import shipped_library
from pcbdyn.fe.modal import solve_modes

from sim_boards import LAYOUTS, board_text

MESH = 10.0


def entry(lib, family, value_mm, std_mm=None):
    """``lib``/FAMILY.toml: the shipped entry with another equivalent thickness (and a std)."""
    text = (shipped_library() / f"{family}.toml").read_text()
    text = re.sub(r'equivalent_thickness = ".*"', f'equivalent_thickness = "{value_mm} mm"'
                  + (f'\nequivalent_thickness_std = "{std_mm} mm"' if std_mm else ""), text)
    lib.mkdir(exist_ok=True)
    (lib / f"{family}.toml").write_text(text)


def frequencies(tmp_path, thickness_mm: dict, name="fd.toml") -> np.ndarray:
    """Elastic frequencies of b1 with each family's parts at ``thickness_mm`` (explicit in the file)."""
    refs = {f"U{i + 1}": thickness_mm.get(fam, 3.5) for i, (fam, _, _) in enumerate(LAYOUTS["b1"][2])}
    path = tmp_path / name
    path.write_text(board_text("b1", MESH, refs))
    return solve_modes(load_board(path).build().model, n_modes=8).frequencies


def build_json(args, tmp_path, env=None) -> dict:
    js = tmp_path / "out.json"
    r = CliRunner(env=env).invoke(main, ["build", *map(str, args), "--json", str(js)])
    assert r.exit_code == 0, r.output
    return json.loads(js.read_text()), r.output


@pytest.fixture
def board(tmp_path):
    path = tmp_path / "b1.toml"
    path.write_text(board_text("b1", MESH))
    return path


def test_library_option_and_path_variable(tmp_path, board):
    """--library DIR is searched first, then PCBDYN_LIBRARY, then the shipped library: each gives the
    frequencies of the board with that library's PGA thickness written on its parts."""
    entry(tmp_path / "cli", "PGA", 5.0)
    entry(tmp_path / "env", "PGA", 4.5)
    got = {}
    for label, args, env in [("shipped", [], None), ("env", [], {"PCBDYN_LIBRARY": str(tmp_path / "env")}),
                             ("cli", ["--library", tmp_path / "cli"], {"PCBDYN_LIBRARY": str(tmp_path / "env")})]:
        data, _ = build_json([board, "--no-pictures", *args], tmp_path, env)
        got[label] = np.array([m["frequency_hz"] for m in data["modes"]])
    for label, t in [("shipped", 3.5), ("env", 4.5), ("cli", 5.0)]:
        assert got[label] == pytest.approx(frequencies(tmp_path, {"PGA": t})[:got[label].size], rel=1e-9), label
    assert np.min(np.abs(got["cli"] / got["shipped"] - 1)) > 0.005  # the families matter


def test_build_uncertainty_matches_resolves(tmp_path, board):
    """sd_f^2 = sum_j (df/dp_j)^2 sd_j^2 (first order, the families independent) against central
    differences of full re-solves at each family's value +- its std; a family without a std, and a
    part with a thickness of its own, add nothing."""
    lib = tmp_path / "lib"
    values, stds = {"PGA": 4.6, "CQFP": 4.2, "JLCC": 2.8}, {"PGA": 0.15, "CQFP": 0.2}
    for fam, v in values.items():
        entry(lib, fam, v, stds.get(fam))
    data, out = build_json([board, "--no-pictures", "--uncertainty", "--library", lib], tmp_path)
    sd = np.array([m["frequency_std_hz"] for m in data["modes"]])
    f0 = np.array([m["frequency_hz"] for m in data["modes"]])
    var = np.zeros(sd.size)
    for fam, s in stds.items():
        up = frequencies(tmp_path, {**values, fam: values[fam] + s})[:sd.size]
        dn = frequencies(tmp_path, {**values, fam: values[fam] - s})[:sd.size]
        var += ((up - dn) / 2) ** 2
    print("\nf [Hz]:", np.round(f0, 1), "\nsd first order [Hz]:", np.round(sd, 3), "\nsd re-solves [Hz]:",
          np.round(np.sqrt(var), 3))
    assert sd == pytest.approx(np.sqrt(var), rel=0.02)
    assert np.all(sd > 0.002 * f0)
    assert set(data["uncertainty"]) == {"PGA", "CQFP"} and data["uncertainty"]["PGA"]["std_m"] == pytest.approx(1.5e-4)
    assert "+- sd [Hz]" in out and "library uncertainty: PGA 4.6 +- 0.15 mm (U1, U5)" in out
    # parts with thicknesses of their own take nothing from the library's std
    own = tmp_path / "own.toml"
    own.write_text(board_text("b1", MESH, {f"U{i + 1}": values[f] + 0.01 for i, (f, _, _) in enumerate(LAYOUTS["b1"][2])}))
    data, out = build_json([own, "--no-pictures", "--uncertainty", "--library", lib], tmp_path)
    assert all(m["frequency_std_hz"] == 0 for m in data["modes"]) and "no part family" in out
