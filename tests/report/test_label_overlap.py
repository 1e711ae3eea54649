"""No two texts of a picture overlap (issue 39: labels overlapped in evidence.png, COMAC and the stabilisation
chart; localisation.png numbered its parameters instead of naming them). Each picture kind is drawn on data
made to crowd it (neighbouring points and effects, close modes, long names), and every text the renderer
draws (titles, axis and tick labels, annotations, legends, colour-bar labels) is boxed: no box may meet
another."""

import itertools
from pathlib import Path
from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text

from pcbdyn.board import load_board

matplotlib.use("Agg")

CARD = Path(__file__).resolve().parents[2] / "examples" / "six_part_card" / "board.toml"


@pytest.fixture
def drawn(monkeypatch):
    """{file name: [(text, box), ...]} of every figure saved while the test runs, as the renderer drew it."""
    pictures, current = {}, []
    draw, savefig = Text.draw, Figure.savefig

    def record(self, renderer):
        draw(self, renderer)
        if self.get_visible() and self.get_text().strip():
            current.append((self.get_text(), self.get_window_extent(renderer)))

    def save(self, fname, *args, **kwargs):
        current.clear()
        self.canvas.draw()
        pictures[Path(str(fname)).name] = list(current)
        return savefig(self, fname, *args, **kwargs)

    monkeypatch.setattr(Text, "draw", record)
    monkeypatch.setattr(Figure, "savefig", save)
    return pictures


def overlapping(texts, pad: float = 1.0) -> list:
    return [(a, b) for (a, A), (b, B) in itertools.combinations(texts, 2)
            if A.x0 + pad < B.x1 and B.x0 + pad < A.x1 and A.y0 + pad < B.y1 and B.y0 + pad < A.y1]


def only(drawn):
    (texts,) = drawn.values()
    assert len(texts) > 5
    return texts


def test_comac_labels_of_neighbouring_points_and_of_an_edge_point_stay_apart(tmp_path, drawn):
    from pcbdyn.report.correlation_plots import comac_map

    xs, ys = np.meshgrid(np.arange(0, 163, 13.5), np.arange(0, 179, 13.5))
    xy = np.c_[xs.ravel(), ys.ravel()] * 1e-3
    values = np.ones(len(xy))
    worst = [k for k, p in enumerate(xy) if abs(p[1] - 0.162) < 1e-9][2:7]  # five neighbours by the top edge
    values[worst] = [0.5, 0.6, 0.55, 0.65, 0.7]
    comac_map(tmp_path / "comac.png", load_board(CARD).outline, xy, values, [f"{k + 1}:+z" for k in range(len(xy))])
    texts = only(drawn)
    assert sum("\n0." in t for t, _ in texts) == 5
    assert not overlapping(texts)


def test_evidence_labels_of_close_effects_and_the_colour_bars_stay_apart(tmp_path, drawn):
    from pcbdyn.report.diagnosis_report import plot_evidence

    xs, ys = np.meshgrid(np.linspace(0, 0.162, 13), np.linspace(0, 0.178, 14))
    xy = np.c_[xs.ravel(), ys.ravel()]
    gain = 2.5e5 * np.exp(-((xy[:, 0] - 0.06) ** 2 + (xy[:, 1] - 0.12) ** 2) / 1e-3)
    evidence = {"point_mass": (xy, gain), "ground_spring": (xy, gain[::-1])}
    effects = [{"type": "point_mass", "at_mm": [60.0, 120.0]}, {"type": "point_mass", "at_mm": [64.0, 121.0]},
               {"type": "ground_spring", "at_mm": [62.0, 116.0]}]
    plot_evidence(tmp_path / "evidence.png", load_board(CARD), evidence, effects)
    texts = only(drawn)
    assert sum(t in ("point_mass", "ground_spring") for t, _ in texts) == 6
    assert not overlapping(texts)


def test_the_numbers_of_close_modes_on_a_stabilisation_chart_stay_apart(tmp_path, drawn):
    from pcbdyn.report.stabilisation import stabilisation_chart

    f_modes = np.array([198.0, 201.0, 204.0, 277.0, 394.0, 396.0, 531.0])
    rng = np.random.default_rng(0)
    order = np.repeat(np.arange(10, 82, 2), f_modes.size)
    chart = SimpleNamespace(frequency=np.tile(f_modes, order.size // f_modes.size) + rng.normal(0, 0.3, order.size),
                            order=order, code=rng.choice(list("ofdvs"), order.size))
    result = SimpleNamespace(chart=chart, band=(150.0, 600.0), modes=SimpleNamespace(frequencies=f_modes,
                             n_modes=f_modes.size), max_order=40, selection="auto")
    f = np.arange(100.0, 700.0, 0.5)
    H = sum(1.0 / (fm**2 - f**2 + 0.02j * fm * f) for fm in f_modes)[:, None, None] * np.ones((1, 3, 1))
    stabilisation_chart(tmp_path / "stabilisation.png", result, SimpleNamespace(frequencies=f, H=H, units="m/s^2/N"))
    texts = only(drawn)
    assert {str(k) for k in range(1, 8)} <= {t for t, _ in texts}
    assert not overlapping(texts)


def test_the_localisation_figure_names_its_parameters_without_overlap(tmp_path, drawn):
    """42 element thicknesses (the thesis' simulated PCB) with long names: the parameters are named, not
    numbered."""
    from pcbdyn.report.localisation_plots import localisation_figure
    from pcbdyn.updating.subset import Subset

    n = 42
    names = [f"components.U{k + 1}.thickness" for k in range(n)]
    rng = np.random.default_rng(1)
    order = rng.permutation(n)
    x = np.zeros(n)
    x[[10, 12, 22, 24]] = [0.066, 0.07, 0.064, 0.069]
    subset = Subset("tls/qr-f", np.array([10, 12, 22, 24]), x, 41, np.geomspace(1, 150, n), order=order,
                    descending_ratio=np.sort(rng.uniform(0, 30, n))[::-1], retained=order[:6])
    localisation_figure(tmp_path / "localisation.png", subset, names)
    texts = only(drawn)
    shown = {t for t, _ in texts}
    assert {names[i] for i in (10, 12, 22, 24)} <= shown and f"1. {names[order[0]]}" in shown
    assert not overlapping(texts)


def test_the_pictures_of_correlate_localize_and_update_on_the_card(tmp_path, drawn):
    """The pictures the commands draw on the six-part card and a simulated test of it (MAC matrix, frequencies,
    shape pairs, COMAC, localisation, FBM map, iterations): no text meets another."""
    from click.testing import CliRunner

    from pcbdyn.cli import main

    def run(*args):
        res = CliRunner().invoke(main, [str(a) for a in args])
        assert res.exit_code == 0, res.output

    card = CARD.parent
    truth = tmp_path / "truth.toml"
    truth.write_text(CARD.read_text().replace('E = "26 GPa"', 'E = "27 GPa"'))
    run("simulate-test", truth, "--points", card / "points.csv", "--excite", "135,63.57", "--noise", "f=0.2,shape=2",
        "--seed", 1, "--out", tmp_path / "t.uff")
    run("correlate", CARD, tmp_path / "t.uff", "--out", tmp_path / "c")
    run("localize", CARD, tmp_path / "t.uff", "--out", tmp_path / "l")
    run("update", CARD, tmp_path / "t.uff", "--params", "E_board,t_PGA", "--max-iter", 3, "--out", tmp_path / "u")
    assert {"mac_matrix.png", "frequencies.png", "comac.png", "localisation.png", "fbm_map.png", "iterations.png"} <= {
        name.split(".pcbdyn~")[0].lstrip(".") + ".png" for name in drawn}
    assert {name: overlapping(texts) for name, texts in drawn.items() if overlapping(texts)} == {}
