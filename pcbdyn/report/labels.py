"""Labels placed on a plot where they overlap no other text: each tries offsets around its anchor, nearest
first, and keeps the first whose box meets none of the labels placed before it nor the texts already on
the figure (titles, axis labels, tick labels)."""

from __future__ import annotations

import numpy as np

#: offsets [points] tried around an anchor, nearest first: right-above, left-above, right-below, ...
OFFSETS = [(dx * r, dy * r) for r in (1.0, 2.2, 3.6, 5.2) for dx, dy in
           ((6, 4), (-6, 4), (6, -4), (-6, -4), (0, 8), (0, -8), (10, 0), (-10, 0))]


def _texts(fig) -> list:
    """The texts the figure shows: titles, axis labels, the tick labels of ticks in view, texts, legends."""
    out = list(fig.texts)
    for ax in fig.axes:
        out += [ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            lo, hi = min(lo, hi), max(lo, hi)
            out += [t for loc, t in zip(axis.get_majorticklocs(), axis.get_majorticklabels()) if lo <= loc <= hi]
        if ax.get_legend() is not None:
            out += ax.get_legend().get_texts()
    return [t for t in out if t.get_visible() and t.get_text().strip()]


#: [pixels] the least gap kept between two texts, so that neighbouring numbers do not read as one
GAP = 3.0


def _meets(a, b) -> bool:
    return a.x0 < b.x1 + GAP and b.x0 < a.x1 + GAP and a.y0 < b.y1 + GAP and b.y0 < a.y1 + GAP


def place_labels(ax, anchors, texts, xycoords="data", offsets=OFFSETS, **style) -> list:
    """Annotate ``ax`` with each of ``texts`` near its anchor (in ``xycoords``), at the first of ``offsets``
    [points] where it overlaps nothing (else the last tried); ``style``: the annotation's text
    properties. Call it once everything else is on the figure (colour bars, titles, aspect): its layout
    is then fixed. Returns the annotations."""
    fig = ax.figure
    fig.canvas.draw()  # the layout and the tick labels as they will be drawn
    fig.set_layout_engine("none")  # kept as it is now: the labels are placed for it
    renderer = fig.canvas.get_renderer()
    taken = [t.get_window_extent(renderer) for t in _texts(fig)]
    placed = []
    for xy, text in zip(anchors, texts):
        for k, (dx, dy) in enumerate(offsets):
            a = ax.annotate(text, tuple(np.asarray(xy, float)), xycoords=xycoords, xytext=(dx, dy),
                            textcoords="offset points", ha="left" if dx > 0 else "right" if dx < 0 else "center",
                            va="bottom" if dy > 0 else "top" if dy < 0 else "center", annotation_clip=False,
                            **style)
            bb = a.get_window_extent(renderer)
            if k == len(offsets) - 1 or not any(_meets(bb, t) for t in taken):
                break
            a.remove()
        taken.append(bb)
        placed.append(a)
    return placed
