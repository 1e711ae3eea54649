"""Candidate generation on a board built from board.toml: the right places."""

import numpy as np
import pytest

from pcbdyn import diagnosis as dg
from pcbdyn.board import build_model, load_board
from data_files import board_text

W, H = 0.1, 0.08
BOARD = board_text("diagnosis_card.toml")


@pytest.fixture(scope="module")
def board(tmp_path_factory):
    path = tmp_path_factory.mktemp("b") / "board.toml"
    path.write_text(BOARD)
    bm = build_model(load_board(path))
    layout = dg.from_structure(bm)
    return bm, layout, dg.generate(layout, segments=4, spacing=0.01, patch=0.025, path_spacing=0.02)


def of(cands, kind):
    return [c for c in cands if c.kind == kind]


def test_points_and_declared_masses_are_prime_point_mass_candidates(board):
    bm, layout, cands = board
    for name in ("points.1", "points.2", "points.3", "masses.tx"):
        node = bm.point_nodes[name]
        hits = [c for c in of(cands, "point_mass") if c.nodes[0] == node]
        assert len(hits) == 1 and hits[0].prime and hits[0].name == f"point_mass@{name}"
        assert np.allclose(hits[0].at, bm.model.nodes[node, :2])
    exc = next(c for c in of(cands, "point_mass") if c.name == "point_mass@points.1")
    assert exc.describe()["at_mm"] == pytest.approx([70.0, 55.0], abs=1e-6)
    assert exc.describe()["type"] == "point_mass" and exc.describe()["unit"] == "kg"


def test_point_grid_covers_the_board_at_the_spacing(board):
    _, layout, cands = board
    xy = np.array([c.at for c in of(cands, "ground_spring")])
    assert len(xy) >= 0.8 * (W / 0.01) * (H / 0.01) * 0.95
    # the right guide holds the strip x > 95 mm: no candidate acts there
    probe = np.stack(np.meshgrid(np.linspace(0.005, 0.09, 10), np.linspace(0.005, 0.075, 8)), -1).reshape(-1, 2)
    assert np.linalg.norm(probe[:, None] - xy[None], axis=2).min(axis=1).max() < 0.01


def test_edge_segments_lie_on_the_outline_or_a_support_line_and_cover_each_edge(board):
    bm, layout, cands = board
    segs = of(cands, "edge_stiffness")
    lines = {"x": (0.0, W, W - 0.005), "y": (0.0, H)}
    for c in segs:
        xy = bm.model.nodes[c.nodes, :2]
        on_x = any(np.allclose(xy[:, 0], v, atol=1e-9) for v in lines["x"])
        on_y = any(np.allclose(xy[:, 1], v, atol=1e-9) for v in lines["y"])
        assert on_x or on_y, c.name
        assert c.data["length"] > 0
    def pieces(cs):  # single pieces ("[i]"), not runs of several ("[i-j]")
        return [c for c in cs if "-" not in c.name.rsplit("[", 1)[1]]

    left = [c for c in segs if np.allclose(c.geometry["segment"][:, 0], 0.0)]
    assert len(pieces(left)) == 4 and len(left) == 10  # 4 pieces, 10 runs of consecutive pieces
    assert sum(c.data["length"] for c in pieces(left)) == pytest.approx(H, rel=1e-9)
    assert max(c.data["length"] for c in left) == pytest.approx(H, rel=1e-9)  # the run of the whole side
    inner = [c for c in segs if np.allclose(c.geometry["segment"][:, 0], W - 0.005)]
    assert len(pieces(inner)) == 4  # the right guide acts on the inner line of its 5 mm strip
    assert not [c for c in segs if np.allclose(c.geometry["segment"][:, 0], W)]  # held strip: dropped
    free = [c for c in segs if np.allclose(c.geometry["segment"][:, 1], 0.0)]
    assert len(pieces(free)) == 4
    lm = of(cands, "line_mass")
    assert {c.name.split("@")[1] for c in lm} < {c.name.split("@")[1] for c in segs}
    # a mass on a guide line whose translations are held does nothing: only free edges remain
    assert {round(float(c.geometry["segment"][0, 1]), 9) for c in lm} == {0.0, H}
    assert len(pieces(lm)) == 8 and len(lm) == 20 and all(np.ptp(c.geometry["segment"][:, 1]) == 0 for c in lm)


def test_each_part_footprint_is_a_region_candidate(board):
    bm, layout, cands = board
    c = next(c for c in of(cands, "region_stiffness") if c.name == "region_stiffness@components.U1")
    assert c.at == pytest.approx((0.035, 0.04), abs=1e-9)  # area centroid of the footprint's cells
    cells = c.data["cells"]["quad4"]  # the footprint's cells and only those
    assert sorted(map(tuple, np.sort(cells, axis=1))) == sorted(map(tuple, np.sort(
        bm.model.sets["components.U1"].conn, axis=1)))
    patches = [c for c in of(cands, "region_stiffness") if "patch" in c.name]
    assert len([c for c in patches if "@patch[" in c.name]) == 4 * 3
    double = [c for c in patches if "@patch2x[" in c.name]  # twice the side: four times the cells
    assert len(double) == 2 * 2
    assert sum(len(c.data["cells"]["quad4"]) for c in double) == sum(
        len(c.data["cells"]["quad4"]) for c in patches if "@patch[" in c.name)
    assert [c for c in patches if "@patch2x+[" in c.name]  # and shifted by half of it


def test_stiffener_paths_follow_rows_columns_and_diagonals_with_their_pieces(board):
    bm, layout, cands = board
    paths = of(cands, "stiffener")
    ends = [np.asarray(c.geometry["path"])[[0, -1]] for c in paths]
    d = [e[1] - e[0] for e in ends]
    rows = [e for e, v in zip(ends, d) if abs(v[1]) < 1e-9]
    cols = [e for e, v in zip(ends, d) if abs(v[0]) < 1e-9]
    whole_rows = [e for e in rows if np.ptp(e[:, 0]) > W - 0.008]
    whole_cols = [e for e in cols if np.ptp(e[:, 1]) > H - 0.008]
    assert len(whole_rows) == 4 and len(whole_cols) == 5  # 20 mm apart across 80 mm and 100 mm
    assert np.allclose(sorted(e[0, 1] for e in whole_rows), [0.01, 0.03, 0.05, 0.07], atol=0.8 * 0.008)
    # each line also in halves at either end and in the middle
    assert len(rows) == 4 * len(whole_rows) and len(cols) == 4 * len(whole_cols)
    for e in rows:
        assert np.ptp(e[:, 0]) == pytest.approx(W, abs=0.008) or np.ptp(e[:, 0]) == pytest.approx(W / 2, abs=0.008)
    slanted = [v for v in d if abs(v[0]) > 1e-9 and abs(v[1]) > 1e-9]
    assert slanted and all(abs(abs(v[1] / v[0]) - 1.0) < 0.25 for v in slanted)  # diagonals at about 45 deg


def test_columns_of_the_board_candidates_are_finite_and_the_prime_suspect_matters(board):
    from pcbdyn.fe.modal import solve_modes

    bm, layout, cands = board
    modes = solve_modes(bm.model, n_modes=6)
    cols = dg.frequency_columns(bm.model, modes, cands)
    assert cols.shape == (6, len(cands)) and np.all(np.isfinite(cols))
    pm = [i for i, c in enumerate(cands) if c.kind == "point_mass"]
    assert np.all(cols[:, pm] <= 1e-12)  # a mass never raises a frequency
    gs = [i for i, c in enumerate(cands) if c.kind in ("ground_spring", "edge_stiffness", "region_stiffness")]
    assert np.all(cols[:, gs] >= -1e-9 * np.abs(cols[:, gs]).max())
