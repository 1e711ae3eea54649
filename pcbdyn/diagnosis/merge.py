"""Shares of one effect reported as one: a diagnosis fits an effect that lies between nodes or
between the candidates' places as shares on the places around it (a mass on the nodes around its
point, a rib on two lines beside it, a region on two overlapping rectangles); :func:`groups` finds
them and :func:`merged` reports each group as one effect, with the uncertainty of the combination."""

from __future__ import annotations

import math

import numpy as np
import shapely

from ..fe.probe import segment_parameter
from .catalogue import kind, weighted_centre
from .fitting import estimate
from .moves import REGION_KINDS, overlap, rectangle
from .selection import adopt
from .stiffener import in_plane, lifted
from .uncertainty import at_state, interval, jackknife_cov, model_form, parts, place_cov, place_range, profile_interval

#: kinds that act at one node: an effect between nodes is shared by its neighbours
POINT_KINDS = ("point_mass", "point_inertia", "ground_spring")
#: [element sizes] how far apart shares of one effect may be found (an unstructured mesh puts the
#: nodes around a point up to about two elements apart)
MERGE_REACH = 2.6


def linked(a, b, reach: float) -> bool:
    """Two chosen effects that are one: point effects of one kind within ``reach`` [m] (a mass or a
    spring between nodes is fitted as shares on the nodes around it), or a point mass within
    ``reach`` of a line mass (a mass spread over part of an edge is fitted as a line plus points),
    line masses whose segments overlap or lie within ``reach``, parallel stiffeners within
    ``reach`` (a rib between two lines is fitted as shares on both), or overlapping rectangular
    regions of one kind (a region between two is fitted as both)."""
    if a.kind == b.kind and a.kind in POINT_KINDS:
        return math.dist(a.at, b.at) <= reach
    if a.kind == b.kind and a.kind in REGION_KINDS and None not in (ra := rectangle(a), rb := rectangle(b)):
        return min(overlap(ra, rb)) > 0.0
    if a.kind == b.kind == "stiffener":  # on one plate, in its plane
        pa, pb = in_plane(a), in_plane(b)
        da, db = np.diff(pa, axis=0)[0], np.diff(pb, axis=0)[0]
        parallel = abs(da[0] * db[1] - da[1] * db[0]) <= 1e-6 * np.linalg.norm(da) * np.linalg.norm(db)
        return a.data.get("plate") == b.data.get("plate") and parallel and _segment_gap(pa, pb) <= reach
    if a.kind == b.kind == "line_mass":  # masses along one stretch of a side add up
        return _segment_gap(a.geometry["segment"], b.geometry["segment"]) <= reach
    if {a.kind, b.kind} == {"point_mass", "line_mass"}:
        line, point = (a, b) if a.kind == "line_mass" else (b, a)
        return _to_segment(np.asarray(point.at, float)[:2], np.asarray(line.geometry["segment"], float)) <= reach
    return False


def _to_segment(p, seg) -> float:
    """Distance [m] from point ``p`` to the straight segment ``seg`` (2, 2)."""
    a, b = seg[:1], seg[1:]
    return float(np.linalg.norm(a + segment_parameter(p[None], a, b)[:, None] * (b - a) - p))


def _segment_gap(s, t) -> float:
    """Shortest distance [m] between two straight segments (0 where they overlap or cross)."""
    s, t = np.asarray(s, float), np.asarray(t, float)

    def side(a, b, p):  # sign of p's side of the line a-b
        (u, v), (w, z) = b - a, p - a
        return np.sign(u * z - v * w)

    if side(*s, t[0]) * side(*s, t[1]) < 0 and side(*t, s[0]) * side(*t, s[1]) < 0:
        return 0.0  # they cross
    return min([_to_segment(p, t) for p in s] + [_to_segment(p, s) for p in t])


def groups(chosen, reach: float, link=linked) -> list:
    """Groups of chosen effects linked (``link(a, b, reach)``, by default :func:`linked`: reported as
    one) directly or through others."""
    from scipy.sparse.csgraph import connected_components

    n = len(chosen)
    joined = np.eye(n, dtype=bool)
    for a in range(n):
        for b in range(a + 1, n):
            joined[a, b] = joined[b, a] = link(chosen[a], chosen[b], reach)
    _, label = connected_components(joined, directed=False)
    return [np.flatnonzero(label == g).tolist() for g in dict.fromkeys(label.tolist())]


def merged(chosen, values, cov, cov_jack, cov_place, group, profile=None, places=None) -> dict:
    """One effect entry (JSON-ready) for a group: the magnitudes summed at their weighted centre (on
    line masses: the place and extent of the largest; parallel stiffeners: their weighted mean
    path; overlapping regions: the mean stiffness change over the area they cover, their union, which
    keeps the change's integral over the board, or their masses summed over it), the uncertainty of
    that combination from the fit's covariance ``cov``, the jackknife's ``cov_jack``, what the places
    leave open ``cov_place`` and the model-form budget (:func:`.uncertainty.parts`), and its 2-sigma
    interval (:func:`.uncertainty.interval`; ``profile``: the chi^2 profile's of a group of one; ``places``:
    its magnitudes over the places the data do not tell apart, :func:`.uncertainty.place_range`)."""
    lines = [k for k in group if chosen[k].kind == "line_mass"]
    c = chosen[max(lines, key=lambda k: values[k]) if lines else group[0]]
    d = c.describe()
    v = np.asarray(values, float)[group]
    w = np.ones(v.size)  # the combination reported: a sum, or for regions an area-weighted mean
    if len(group) > 1:
        d["name"] = "+".join(chosen[k].name for k in group)
        d["merged_at_mm"] = np.round(1e3 * np.array([chosen[k].at for k in group]), 3).tolist()
        if c.kind in REGION_KINDS:
            boxes = [shapely.box(*rectangle(chosen[k])) for k in group]
            union = shapely.union_all(boxes)
            if c.kind == "region_stiffness":
                w = np.array([b.area for b in boxes]) / union.area
            d["polygon_mm"] = np.round(1e3 * np.asarray(union.exterior.coords)[:-1], 3).tolist()
            d["at_mm"] = np.round(1e3 * np.asarray(union.centroid.coords)[0], 3).tolist()
        elif not lines:
            d["at_mm"] = np.round(1e3 * weighted_centre([chosen[k] for k in group], v), 3).tolist()
        if c.kind == "stiffener":
            d["path_mm"] = np.round(1e3 * lifted(c, mean_path([chosen[k] for k in group], v)), 3).tolist()
    if hasattr(c.spec, "mass"):  # a rib carries its mass: its section's, at the stiffness found
        d["mass_kg"] = float(sum(chosen[k].spec.mass(chosen[k], values[k]) for k in group))
        sec = c.spec.section_of(c)
        d["section_height_mm"] = round(1e3 * sec.h, 4)
        d["section_material"] = {"E_Pa": sec.E, "nu": sec.nu, "rho_kg_m3": sec.rho}
        if "normal" in c.data:  # the side of a housing's plate it stands on (:mod:`.plate_view`)
            d["normal"] = np.round(c.data["normal"], 12).tolist()
    sub = np.ix_(group, group)
    u = parts(float(w @ v), w, cov[sub] if cov.size else cov, cov_jack[sub], cov_place[sub], places, model_form(c.kind))
    d["interval_2sigma"] = interval(float(w @ v), u, profile, c.spec.lower)
    d.update(magnitude=float(w @ v), uncertainty=u.pop("total"), uncertainty_parts=u, kind=c.kind)
    return d


def reported(res, sel, chosen, neighbours, reach: float, bounds=None) -> list:
    """The effects entries (JSON-ready) of the selection ``sel`` of effects ``chosen``: shares within
    ``reach`` [m] as one (:func:`groups`, :func:`merged`), each with its uncertainty (:mod:`.uncertainty`:
    the fit's covariance, the jackknife over the folds, what the places leave open, ``neighbours(c)``
    giving candidate c's places one step away, and for an effect alone the profile over its places,
    :func:`.uncertainty.place_range`) and its 2-sigma interval, from the chi^2 profile where one
    effect alone is of a kind that saturates (:func:`.uncertainty.profile_interval`)."""
    scale = np.array([c.spec.scale for c in chosen])
    cov_jack = jackknife_cov(res, sel.state, chosen, scale)
    at = at_state(res, sel.state) if chosen else None  # one reanalysis for every quick fit below
    cov_place = place_cov(res, sel.state, chosen, scale, neighbours, at)
    out = []
    for g in groups(chosen, reach):
        spec = kind(chosen[g[0]].kind)
        alone = len(g) == 1 and getattr(spec, "reanalysed", True)
        saturates = alone and getattr(spec, "saturates", False) and sel.values[g[0]] > 0
        profile = profile_interval(res, sel.state, chosen, g[0], bounds, at) if saturates else None
        places = place_range(res, sel.state, chosen, g[0], neighbours, bounds, at) if alone else None
        out.append(merged(chosen, sel.values, sel.cov, cov_jack, cov_place, g, profile, places))
    return out


def mean_path(stiffeners, values) -> np.ndarray:
    """The line (2, 2) [m] in their plate's plane of parallel ``stiffeners`` fitted as shares of one rib:
    their end points' mean weighted by their ``values`` (EI)."""
    v = np.asarray(values, float)
    share = v / v.sum() if v.sum() > 0 else np.full(v.size, 1.0 / v.size)
    paths = np.array([in_plane(c) for c in stiffeners])
    return np.einsum("g,gij->ij", share, paths)


def resolved(res, cands, sel, neighbours, reach: float, bounds, pen: float) -> tuple:
    """(selection, effects entries, unresolved entries) of the selection ``sel`` of candidates ``cands``
    (:func:`reported`'s other arguments): while an effect's reported standard deviation (every part:
    the noise, the folds, the places, the model form) is at least its magnitude, the least resolved is
    left out and the others refitted (``pen``: one effect's criterion cost). Its removal may be noticed
    (:func:`.select.noticed`): the data say that something acts there, not what nor how much (a mass
    hugging a held edge trades its size against its distance from it, m x^2), so it is listed apart,
    not put in the model. The covariance's own rule (:func:`.select.without_vanished`) misses these: its
    places are fixed. An interval open above (a spring the profile finds as stiff as a pin) is resolved.
    Dev boards and housings as diagnosed at 5d70d4e: five effects so, all five invented, none matching a truth."""
    gone = []
    while True:
        chosen = [cands[i] for i in sel.chosen]
        effects = reported(res, sel, chosen, neighbours, reach, bounds)
        weak = {k: e["uncertainty"] / max(abs(e["magnitude"]), 1e-300) for k, e in enumerate(effects)
                if e["interval_2sigma"][1] is not None and not e["uncertainty"] < abs(e["magnitude"])}
        if not weak:
            return sel, effects, gone
        k = max(weak, key=weak.get)
        drop = groups(chosen, reach)[k]
        keep = [i for j, i in enumerate(sel.chosen) if j not in drop]
        fit = estimate(res, sel.p, [cands[i] for i in keep], np.delete(sel.values, drop), 8, bounds)
        if fit.state is None:
            return sel, effects, gone
        gone.append(effects[k])
        sel = adopt(sel, keep, fit, pen)
