"""Mode-shape pictures carry what an engineer needs to read them: the quantity on a colour bar, a
top view in mm beside the 3-D one, the outlines of parts, fixtures and masses, and the board,
configuration, mode and frequency in the title."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.image import AxesImage
from matplotlib.tri import Triangulation

from pcbdyn.report.pictures import QUANTITY, mode_figure

PART = [[0.02, 0.02], [0.05, 0.02], [0.05, 0.04], [0.02, 0.04]]
OUTLINES = [
    {"kind": "board", "label": "", "xy": [[0, 0], [0.1, 0], [0.1, 0.08], [0, 0.08]], "closed": True},
    {"kind": "part", "label": "U1", "xy": PART, "closed": True},
    {"kind": "fixture", "label": "guide", "xy": [[0, 0], [0.1, 0]], "closed": False},
    {"kind": "mass", "label": "m1", "xy": [[0.07, 0.05]], "closed": False},
]


def plate_tri():
    x, y = np.meshgrid(np.linspace(0, 100, 11), np.linspace(0, 80, 9))
    tri = Triangulation(x.ravel(), y.ravel())
    w = np.sin(np.pi * tri.x / 100) * np.sin(np.pi * tri.y / 80)
    return tri, w / np.abs(w).max()


@pytest.mark.parametrize("view3d", [None, np.ones((60, 80, 3))])
def test_a_mode_picture_has_colour_bar_mm_top_view_outlines_and_configuration(view3d):
    tri, w = plate_tri()
    fig = mode_figure(tri, w, OUTLINES, "plate [loaded]: mode 1, 123.4 Hz", view3d)
    try:
        bars = [ax for ax in fig.axes if ax.get_ylabel() == QUANTITY]
        assert QUANTITY == "w (normalised)" and len(bars) == 1
        assert bars[0].get_ylim() == pytest.approx((-1.0, 1.0))
        top = next(ax for ax in fig.axes if ax.get_xlabel() == "x [mm]" and ax.name == "rectilinear")
        assert top.get_ylabel() == "y [mm]"
        assert top.get_xlim()[1] == pytest.approx(100, abs=1) and top.get_ylim()[1] == pytest.approx(80, abs=1)
        drawn = [np.column_stack(line.get_data()) for line in top.get_lines()]
        assert any(d.shape == (5, 2) and np.allclose(d[:4], np.asarray(PART) * 1e3) for d in drawn)  # the part, closed
        assert any(d.shape == (1, 2) and np.allclose(d, [[70, 50]]) for d in drawn)  # the mass, a marker
        assert {"U1", "guide", "m1"} <= {t.get_text() for t in top.texts}
        assert {"parts", "fixtures", "masses"} == {t.get_text() for t in top.get_legend().get_texts()}
        assert "[loaded]" in fig._suptitle.get_text() and "123.4 Hz" in fig._suptitle.get_text()
        others = [ax for ax in fig.axes if ax not in bars and ax is not top]
        assert len(others) == 1  # the 3-D view beside the top view
        if view3d is None:
            assert others[0].name == "3d" and others[0].get_xlabel() == "x [mm]"
        else:
            assert any(isinstance(a, AxesImage) for a in others[0].get_images())
    finally:
        plt.close(fig)
