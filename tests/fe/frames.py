"""A non-planar frame of three members (steel, aluminium, steel) shared by the FE tests."""

import numpy as np

from pcbdyn.fe.model import Model
from pcbdyn.fe.properties import BeamProperty


def three_member_frame(corners, n_el: int) -> Model:
    """Three straight members through ``corners`` (4, 3) [m], ``n_el`` beam elements each, no supports."""
    corners = np.asarray(corners, dtype=float)
    pts, conn = [corners[0]], []
    for a, b in zip(corners[:-1], corners[1:]):
        for t in np.linspace(0, 1, n_el + 1)[1:]:
            pts.append(a + t * (b - a))
            conn.append([len(pts) - 2, len(pts) - 1])
    model = Model(np.array(pts))
    conn = np.array(conn)
    props = [
        BeamProperty(210e9, 0.3, 7850, 1e-4, 2e-9, 3e-9, 4e-9, orientation=(0, 0, 1)),
        BeamProperty(70e9, 0.33, 2700, 2e-4, 4e-9, 1e-9, 3e-9, orientation=(0, 0, 1)),
        BeamProperty(210e9, 0.3, 7850, 1.5e-4, 3e-9, 3e-9, 5e-9, orientation=(1, 0, 0)),
    ]
    for i, p in enumerate(props):
        model.add(f"b{i}", "beam2", conn[i * n_el:(i + 1) * n_el], p)
    return model
