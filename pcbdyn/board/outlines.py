"""What a mode-shape picture outlines, gathered from a board as plain data (report/ formats it and
does not know the board): the outline and its holes, the parts' footprints, the fixtures (edge
support lines, contact strips, standoff pads, point springs, edge springs), the point masses of
the base board and of the configuration, and the declared effects (line masses, stiffeners,
regions). Each item is ``{"kind", "label", "xy": [[x, y], ...] in metres, "closed"}``; a single
point is a marker."""

from __future__ import annotations

import numpy as np

from ..fixtures.supports import pad_polygon, strip_polygon, support_line


def _item(kind: str, label: str, xy, closed: bool = False) -> dict:
    return {"kind": kind, "label": label, "xy": np.asarray(xy, dtype=float).reshape(-1, 2).tolist(),
            "closed": closed}


def _fixture(board, f) -> list:
    if f.edge is not None:
        axis, value, lo, hi = support_line(board.outline, f)
        ends = [[value, lo], [value, hi]] if axis == 0 else [[lo, value], [hi, value]]
        strip = strip_polygon(board.outline, f)
        return [_item("fixture", f.name, ends)] + ([_item("fixture", "", strip, True)] if strip is not None else [])
    if f.type == "standoff":
        return [_item("fixture", f.name, pad_polygon(f), True)]
    if f.type == "point_spring":
        return [_item("fixture", f.name, [f.at])]
    if f.type == "edge_spring":
        return [_item("fixture", f.name, f.segment)]
    return []  # free


def board_outlines(board, config: str | None = None) -> list:
    """The outlines of ``board`` (and of configuration ``config``'s added masses) for pictures."""
    items = [_item("board", "", board.outline.vertices, True)]
    items += [_item("board", "", h, True) for h in board.outline.holes]
    items += [_item("part", c.ref, c.corners(), True) for c in board.components]
    for f in board.fixtures:
        items += _fixture(board, f)
    items += [_item("mass", m.name, [m.at]) for m in board.masses]
    added = board.configuration(config).masses if config else []
    items += [_item("mass", f"{m.name} ({config})", [m.at]) for m in added]
    items += [_item("line mass", e.name, e.segment) for e in board.line_masses]
    items += [_item("stiffener", e.name, e.path) for e in board.stiffeners]
    items += [_item("region", e.name, e.polygon, True) for e in board.regions]
    return items
