"""Nastran export: the deck read back by pyNastran (its own venv) has the expected cards and total
mass, and the model rebuilt from pyNastran's cards has the frequencies of the model written."""

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from nastran_rebuild import MatrixShell, rebuild
from nastran_venv import read_deck

from pcbdyn.board import build_model, load_board
from pcbdyn.cli import main
from pcbdyn.exchange import nastran_deck, write_nastran
from pcbdyn.exchange.bulk import card, field
from pcbdyn.fe import (BeamProperty, EdgeSpringProperty, EmbeddedBeamProperty, MassProperty, Model, ShellProperty,
                       SpringProperty)
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.generate import rectangle
from pcbdyn.fe.modal import solve_modes

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
N_MODES = 8


def z_mass(model) -> float:
    _, M = assemble(model)
    r = np.zeros(model.n_dof)
    r[2::6] = 1.0
    return float(r @ (M @ r))


def expected_counts(model) -> dict:
    """Cards the writer's mapping implies, counted from the model's own sets and constraints."""
    n = {"GRID": model.n_nodes, "CQUAD4": 0, "CTRIA3": 0, "CONM2": 0, "CELAS2": 0, "CBAR": 0, "CBUSH": 0, "MPC": 0}
    fixed = set(model.fixed)
    n["MPC"] = sum(1 for s, _ in model.mpcs if s not in fixed)
    for es in model.sets.values():
        cells = len(es.conn)
        if es.etype in ("quad4", "tri3"):
            n["CQUAD4" if es.etype == "quad4" else "CTRIA3"] += cells
        elif es.etype == "mass":
            n["CONM2"] += cells
            if es.conn.shape[1] > 1:  # a body grid tied by six MPCs
                n["GRID"] += cells
                n["MPC"] += 6 * cells
        elif es.etype == "spring":
            n["CELAS2"] += cells * np.count_nonzero(es.prop.k)
        elif es.etype == "edge_spring":
            n["CELAS2"] += 3 * cells * np.count_nonzero(es.prop.k)
        elif es.etype == "beam2":
            n["CBAR"] += cells
        elif es.etype == "embedded_beam2":
            n["CBAR"] += cells
            n["GRID"] += 2 * cells
            n["MPC"] += 12 * cells
    return {k: v for k, v in n.items() if v}


def check_round_trip(model, tmp_path, name, n_modes=N_MODES):
    """Write, read with pyNastran, rebuild, solve; returns (deck, pyNastran's reading, max rel df)."""
    path = tmp_path / f"{name}.bdf"
    deck = write_nastran(path, model, n_modes)
    read = read_deck(path)
    assert read["mass"] == pytest.approx(z_mass(model), rel=1e-9)
    a = solve_modes(model, n_modes)
    b = solve_modes(rebuild(read), n_modes)
    assert b.frequencies.size == a.frequencies.size == n_modes
    assert b.n_rigid == a.n_rigid
    return deck, read, float(np.max(np.abs(b.frequencies / a.frequencies - 1.0)))


@pytest.mark.parametrize("example, config", [("plain_plate", None), ("wedge_locked", None), ("six_part_card", "c2")])
def test_board_decks_read_by_pynastran_rebuild_to_the_same_frequencies(tmp_path, example, config):
    """plain_plate: laminate (MAT2), standoffs (rigid links as MPC, springs), a lumped part tied by
    MPCs; wedge_locked: SPC1 and consistent edge springs as CELAS2; six_part_card c2: a mass with
    rotary inertia on its footprint (CONM2 on a body grid tied by MPCs)."""
    bm = build_model(load_board(EXAMPLES / example / "board.toml"), config)
    deck, read, df = check_round_trip(bm.model, tmp_path, example)
    want = expected_counts(bm.model)
    assert {k: read["card_count"].get(k, 0) for k in want} == want
    rigid = 6 if example == "six_part_card" else 0  # the free card; Nastran counts its rigid-body modes in ND
    assert read["card_count"]["EIGRL"] == 1 and read["eigrl"]["1"]["nd"] == N_MODES + rigid
    assert read["card_count"]["PSHELL"] == sum(es.etype in ("quad4", "tri3") for es in bm.model.sets.values())
    assert ("SPC1" in read["card_count"]) == bool(bm.model.fixed)
    # isotropic sections are exact; the laminate's rotary inertia is the one inexact quantity (noted)
    assert df < (1e-4 if example == "plain_plate" else 1e-9)
    assert bool(deck.notes) == (example == "plain_plate")


def _fe_model():
    """A plate with quads and triangles, an offset Timoshenko rib on a node row, an embedded beam
    across cells, footprint masses, springs along an oblique and a straight line, a rigid link."""
    a, b, nx, ny = 0.12, 0.08, 12, 8
    nodes, quads = rectangle(a, b, nx, ny)
    m = Model(nodes, free=True)
    last = quads[:, 0] % (nx + 1) == nx - 1
    alu = ShellProperty(70e9, 0.33, 2700.0, 2e-3, nsm=0.4)
    m.add("plate", "quad4", quads[~last & (quads[:, 0] // (nx + 1) < 4)], alu)
    A = np.array([[3.0e8, 4.0e7, 0.0], [4.0e7, 2.0e8, 0.0], [0.0, 0.0, 6.0e7]])
    ortho = MatrixShell(A, A * 2e-3**2 / 10.0, 1.5e7 * np.eye(2), 6.0, 4.0e-7, 2e-3)
    m.add("orthotropic", "quad4", quads[~last & (quads[:, 0] // (nx + 1) >= 4)], ortho)
    m.add("plate.tri3", "tri3", np.vstack([quads[last][:, [0, 1, 2]], quads[last][:, [0, 2, 3]]]), alu)
    row = 4 * (nx + 1) + np.arange(nx + 1)
    rib = BeamProperty(70e9, 0.33, 2700.0, 3e-5, 2.5e-11, 4e-12, 1.2e-11, orientation=(0.0, 0.3, 1.0),
                       offset=(0.0, 0.0, 4e-3), shear_area_y=2.5e-5, shear_area_z=2.5e-5, rotary_inertia=False)
    m.add("rib", "beam2", np.column_stack([row[:-1], row[1:]]), rib)
    cells = quads[[2 * nx + 1, 3 * nx + 5]]
    m.add("embedded", "embedded_beam2", [np.concatenate(cells)],
          EmbeddedBeamProperty(rib, np.full((1, 2, 8), 0.0) + np.kron(np.eye(2), np.full(4, 0.25))[None]))
    patch = np.array([j * (nx + 1) + i for j in (5, 6, 7) for i in (2, 3, 4)])
    patch = np.r_[patch[4], np.delete(patch, 4)]
    m.add("body", "mass", [patch], MassProperty(0.03, (2e-6, 3e-6, 1e-6)))
    W = 0.5 * np.eye(9)[[0, 1, 3, 6, 8]] + 0.5 * np.eye(9)[[0, 0, 0, 0, 0]]
    m.add("sampled", "mass", [np.r_[patch[0] + 3, patch[1:] + 3]], MassProperty(0.01, (1e-6, 1e-6, 0.0), footprint=W))
    diag = np.column_stack([quads[last][:, 0], quads[last][:, 2]])
    m.add("oblique", "edge_spring", diag, EdgeSpringProperty(k=(2e3, 0.0, 5e3, 20.0, 0.0, 0.0)))
    x0 = np.arange(ny + 1) * (nx + 1)
    m.add("guide", "edge_spring", np.column_stack([x0[:-1], x0[1:]]), EdgeSpringProperty(k=(0, 0, 1e5, 15.0, 0, 0)))
    m.add("corner", "spring", [[nx]], SpringProperty(k=(1e4, 1e4, 1e4, 0.0, 0.0, 0.0)))
    m.add("pair", "spring", [[3, 4 + nx + 1]], SpringProperty(k=(0.0, 0.0, 2e4, 0.0, 0.0, 0.0)))
    hub = int(m.add_nodes([[0.09, 0.02, 0.01]])[0])
    m.rigid_link(hub, [1 * (nx + 1) + 8, 1 * (nx + 1) + 9, 2 * (nx + 1) + 8, 2 * (nx + 1) + 9])
    J = np.array([[1e-5, 3e-6, 1e-6], [3e-6, 1.2e-5, -2e-6], [1e-6, -2e-6, 2e-5]])  # products of inertia too
    m.add("hub", "mass", [[hub]], MassProperty(0.05, J))
    m.fix([ny * (nx + 1)], ("ux", "uy"))
    return m


def test_fe_model_with_beams_bodies_and_oblique_springs_round_trips(tmp_path):
    """Cards pcbdyn's boards do not use yet (CTRIA3, MAT2 of an orthotropic section, CBAR with
    offset, orientation and shear, embedded beam ends tied by MPC, CBUSH in a CORD2R frame)."""
    model = _fe_model()
    deck, read, df = check_round_trip(model, tmp_path, "fe_model", n_modes=10)
    assert df < 1e-9
    want = expected_counts(model)
    oblique = len(model.sets["oblique"].conn)
    want["CELAS2"] -= 3 * oblique * 3  # the oblique line's three springs are CBUSH in its frame
    want["CBUSH"] = 3 * oblique
    got = read["card_count"]
    assert {k: got.get(k, 0) for k in want} == want
    assert got["CORD2R"] == 1 and got["PBUSH"] == 3 * oblique and got["PBAR"] == 2 and got["MAT2"] == 3
    assert deck.notes == []


def test_beam_and_laminate_limits_are_named_in_the_notes():
    nodes, quads = rectangle(0.1, 0.1, 2, 2)
    m = Model(nodes)
    m.add("plate", "quad4", quads, ShellProperty(70e9, 0.3, 2700.0, 1e-3))
    m.add("rib", "beam2", [[0, 1]], BeamProperty(70e9, 0.3, 2700.0, 1e-5, 1e-12, 1e-12, 2e-12, linear_bending=True))
    notes = nastran_deck(m, 4).notes
    assert any("rib" in n and "rotary inertia" in n for n in notes)
    assert any("rib" in n and "linear Timoshenko" in n for n in notes)


def test_large_fields_keep_ten_digits_and_fit():
    for x in (1.0 / 3.0, -2.718281828459045e-100, 6.02214076e23, 0.0):
        text = field(x)
        assert len(text) == 16 and float(text) == pytest.approx(x, rel=1e-9, abs=0.0)
    lines = card("CBAR", [1, 2, 3, 4, 0.0, 0.0, 1.0, None, None, None, 0.0, 0.0, 1e-3]).splitlines()
    assert [ln[:8].strip() for ln in lines] == ["CBAR*", "*", "*", "*"]
    assert all(len(ln) <= 72 for ln in lines)
    with pytest.raises(ValueError):
        field(float("nan"))


WEDGE = EXAMPLES / "wedge_locked" / "board.toml"


def test_export_command_json_and_updated_values(tmp_path):
    src = tmp_path / "board.toml"
    shutil.copy(WEDGE, src)
    text = src.read_text()
    upd = tmp_path / "board.updated.toml"
    upd.write_text(text.replace('thickness = "3.19 mm"', 'thickness = "4.25 mm"', 1))
    runner = CliRunner()
    res = runner.invoke(main, ["export", str(src), "--nastran", str(tmp_path / "m.bdf"), "--updated", str(upd),
                               "--json", str(tmp_path / "m.json")])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "m.json").read_text())
    assert data["updated"] == {"components.U1.thickness": {"from": pytest.approx(3.19e-3), "to": pytest.approx(4.25e-3)}}
    bm = build_model(load_board(upd))
    assert data["mass_kg"] == pytest.approx(bm.mass(), rel=1e-12)
    assert data["cards"] == {**expected_counts(bm.model), "EIGRL": 1, "MAT1": 7, "PSHELL": 7, "SPC1": 1}
    pid = next(s["pid"] for s in data["sets"] if s["set"] == "components.U1")
    deck = (tmp_path / "m.bdf").read_text()
    pshell = re.search(rf"^PSHELL\*\s+{pid}\s+\d+\s+(\S+)", deck, re.M)
    assert float(pshell.group(1)) == pytest.approx(4.25e-3, rel=1e-12)
    assert "components.U1.thickness: 0.00319 -> 0.00425" in deck


def test_export_bad_input_gets_clear_errors(tmp_path):
    runner = CliRunner()
    other = tmp_path / "other.toml"
    other.write_text((EXAMPLES / "plain_plate" / "board.toml").read_text())
    res = runner.invoke(main, ["export", str(WEDGE), "--nastran", str(tmp_path / "a.bdf"), "--updated", str(other)])
    assert res.exit_code == 2 and "other.toml is not an update of board.toml" in res.output
    broken = tmp_path / "broken.toml"
    broken.write_text(WEDGE.read_text().replace('at = ["40.5 mm", "38.14 mm"]', 'at = ["400 mm", "38.14 mm"]'))
    res = runner.invoke(main, ["export", str(broken), "--nastran", str(tmp_path / "b.bdf")])
    assert res.exit_code == 2 and "broken.toml" in res.output and "components[0].at" in res.output
    assert "Traceback" not in res.output
    assert not (tmp_path / "a.bdf").exists() and not (tmp_path / "b.bdf").exists()


def test_eigrl_asks_a_free_board_for_its_rigid_body_modes_besides_the_elastic_ones(tmp_path):
    """Nastran's EIGRL ND counts every root, rigid-body ones included: asking a free card for 7 gave 1
    elastic mode and 6 rigid-body ones (the deck asked for 7); a wedge-locked board has none to add."""
    for example, rigid in (("six_part_card", 6), ("wedge_locked", 0)):
        board = EXAMPLES / example / "board.toml"
        res = CliRunner().invoke(main, ["export", str(board), "--nastran", str(tmp_path / "m.bdf"), "--modes", 7,
                                        "--json", str(tmp_path / "m.json")])
        assert res.exit_code == 0, res.output
        assert solve_modes(build_model(load_board(board)).model, n_modes=1).n_rigid == rigid
        eigrl = re.search(r"^EIGRL\*\s+1\s+(\S+)$", (tmp_path / "m.bdf").read_text(), re.M)
        assert int(eigrl.group(1)) == 7 + rigid
        assert json.loads((tmp_path / "m.json").read_text())["eigrl_nd"] == 7 + rigid
