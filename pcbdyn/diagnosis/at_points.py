"""A point mass or a spring to ground found on the nodes of the search's grid placed at its point between
them (issue 37: the generated benchmark's effects lie anywhere, never on a node), by the pattern search
that walks a line mass's ends (:func:`.mass_lines.walked_in`)."""

from __future__ import annotations

import numpy as np

from .catalogue import weighted_centre
from .mass_lines import masses_found, walked_in
from .merge import groups
from .moves import at_grid_node
from .selection import ALPHA, penalty


def _springs(chosen, values, groups) -> list:
    """:func:`.mass_lines.masses_found`' tuples for the springs to ground found on nodes (a group of shares
    on nodes)."""
    v = np.asarray(values, float)
    return [(g, g, float(v[g].sum()), weighted_centre([chosen[k] for k in g], v[g])[:2]) for g in groups
            if all(chosen[k].kind == "ground_spring" and at_grid_node(chosen[k]) for k in g)]


def _points(layout, home):
    """The points a pattern search tries: (x, y) [m] -> [an effect like ``home`` there, between the nodes
    (its kind's ``at_point``)], None off the plate."""
    def build(xy):
        c = home.spec.at_point(layout, home, xy)
        return None if c is None else [c]
    return build


def as_points(res, candidates: list, sel, reach: float, layout, step: float, bounds=None, newton_steps: int = 8,
              alpha: float = ALPHA):
    """``sel`` with each mass or spring to ground found on nodes (one node, or shares on nodes within
    ``reach`` [m] reported as one, :func:`.merge.groups`) refitted as one at a point between the nodes,
    walked from its (shares') centre from steps of ``step`` [m] (half the model's element size), where
    that lowers the criterion. Forward selection finds an effect on the node nearest to it, or as shares
    on two nodes; the generated benchmark's lie anywhere (dev seed 4's 32.5 g, found as 35.2 g on two
    nodes with their centre 2.2 mm off, is placed 0.4 mm off as 32.9 g). Candidates are appended to
    ``candidates``; ``sel`` is updated in place."""
    if not layout.planar:
        return sel
    pen = penalty(res.n_rows, len(candidates), alpha)
    start = list(sel.chosen)  # a walk re-orders and shortens sel.chosen: groups hold positions in this one
    chosen = [candidates[i] for i in start]
    grouped = groups(chosen, reach)
    for g, gm, m, centre in masses_found(chosen, sel.values, grouped) + _springs(chosen, sel.values, grouped):
        ids = [start[k] for k in g]
        if len(g) != len(gm) or not all(at_grid_node(chosen[k]) for k in gm) or not m > 0 or not set(ids) <= set(sel.chosen):
            continue
        build = _points(layout, chosen[gm[0]])
        first = build(centre)
        if first is not None:
            walked_in(res, candidates, sel, ids, m, first[0], np.asarray(centre, float), build, step, bounds,
                      newton_steps, pen, 0.0)
    return sel
