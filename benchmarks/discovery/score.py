"""Judging a diagnosis of a drawn case against its truth (issue 37's acceptance, per case).

Each hidden effect is one or two *atoms*, each a kind diagnose reports (its JSON ``type``), a place
and a magnitude: a bracket is a point mass and a ground spring at one point, a heat sink a region
whose stiffness changes by E_sink / E_board - 1 and a point mass at its centre (a mass reported over a
region is judged as a point mass, :func:`judged_as`), an undeclared
standoff a ground spring (rigid: its stiffness is not judged). An atom is found when a reported
effect of its type lies within :data:`PLACE_MM` (points, regions: from the region's centre, 0 inside
the reported polygon) or :data:`LINE_MM` (stiffeners, line masses, edge stiffness: the farther of
the two ends' distances to the reported line) and its magnitude is within :data:`MAGNITUDE` of the
truth. A reported effect that matches no atom (of any size, by type and place) is invented.
"""

from __future__ import annotations

import numpy as np

PLACE_MM = 15.0
LINE_MM = 30.0
MAGNITUDE = 0.30
LINES = ("stiffener", "line_mass", "edge_stiffness")


def atoms(case: dict, E_board: float) -> list:
    """[(effect index, type, geometry {at | segment | rect}, magnitude or None)] of the case's effects."""
    out = []
    for i, e in enumerate(case["effects"]):
        k = e["kind"]
        if k in ("point_mass", "bracket"):
            out.append((i, "point_mass", {"at": e["at"]}, e["mass"]))
        if k in ("bracket", "ground_spring"):
            out.append((i, "ground_spring", {"at": e["at"]}, e["k"]))
        if k == "standoff":
            out.append((i, "ground_spring", {"at": e["at"]}, None))
        if k == "stiffener":
            out.append((i, "stiffener", {"segment": e["path"]}, e["EI"]))
        if k == "line_mass":
            out.append((i, "line_mass", {"segment": e["segment"]}, e["mass"]))
        if k == "edge_stiffness":
            out.append((i, "edge_stiffness", {"segment": e["segment"]}, e["k_rot"]))
        if k == "heat_sink":
            (x, y), (a, b) = e["at"], e["size"]
            out.append((i, "region_stiffness", {"rect": [x - a / 2, y - b / 2, x + a / 2, y + b / 2]},
                        e["E"] / E_board - 1.0))
            out.append((i, "point_mass", {"at": e["at"]}, e["mass"]))
        if k == "region":
            out.append((i, "region_stiffness", {"rect": e["rect"]}, e["factor"] - 1.0))
    return out


def judged_as(r: dict) -> str:
    """The atom type a reported effect is judged as: a mass spread over a region (``region_mass``) is a
    mass at its place, judged as a ``point_mass`` (its distance: 0 where its polygon holds the atom); a
    ``point_mass`` whose parameter is its rotary inertia [kg m^2] is not a mass (no drawn effect has
    one): ``point_inertia``, which matches no atom (dev seed 22 reports one alone)."""
    if r.get("type") == "point_mass" and r.get("parameter") == "inertia":
        return "point_inertia"
    return "point_mass" if r.get("type") == "region_mass" else r.get("type")


def to_polyline(p, pts) -> float:
    """Distance of point ``p`` to the polyline through ``pts`` (one point: to that point), in 2-D (a board)
    or 3-D (a housing)."""
    pts = np.asarray(pts, float).reshape(-1, np.size(p))
    if len(pts) == 1:
        return float(np.linalg.norm(p - pts[0]))
    a, b = pts[:-1], pts[1:]
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
    return float(np.linalg.norm(a + t[:, None] * ab - p, axis=1).min())


def _reported_line(r: dict):
    for key in ("path_mm", "segment_mm"):
        if r.get(key):
            return np.asarray(r[key], float)
    return np.asarray([r["at_mm"]], float)


def distance(r: dict, geometry: dict) -> float:
    """[mm] how far reported effect ``r`` lies from an atom's geometry."""
    if "segment" in geometry:
        line = _reported_line(r)
        return max(to_polyline(np.asarray(p, float), line) for p in geometry["segment"])
    if "rect" in geometry:
        x0, y0, x1, y1 = geometry["rect"]
        p = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    else:
        p = np.asarray(geometry["at"], float)
    if r.get("polygon_mm"):
        from matplotlib.path import Path as PolyPath

        poly = np.asarray(r["polygon_mm"], float)
        if PolyPath(poly).contains_point(p):
            return 0.0
    return float(np.linalg.norm(np.asarray(r["at_mm"], float) - p))


def _covered(reported: dict, magnitude: float, k: float = 2.0) -> bool:
    """The true ``magnitude`` lies in the reported k-sigma interval: the 2-sigma one (``interval_2sigma``,
    its upper end None where the data leave it open; results written before it: magnitude -+ 2
    uncertainty) with its reach either side scaled by k / 2 (the 1-sigma interval of a linear magnitude)."""
    m = reported["magnitude"]
    if "interval_2sigma" not in reported:
        return abs(m - magnitude) <= k * (reported.get("uncertainty") or 0.0)
    lo, hi = reported["interval_2sigma"]
    return m - k / 2.0 * (m - lo) <= magnitude and (hi is None or magnitude <= m + k / 2.0 * (hi - m))


def judge(truth: dict, result: dict, detectable_chi2: float) -> dict:
    """Per case: atoms (found or not, detectable or not, magnitude error, 1- and 2-sigma covered), the
    reported effects that match no atom (invented), noise-only cleanliness and the errors."""
    case = truth["case"]
    E_board = next((p["true"] for p in case["parameters"] if p["name"] == "E_board"), case.get("E"))
    reported = result.get("effects", []) if result else []
    used = set()
    rows = []
    for i, typ, geom, mag in atoms(case, E_board):
        tol = LINE_MM if typ in LINES else PLACE_MM
        same = [(distance(r, geom), j) for j, r in enumerate(reported) if judged_as(r) == typ]
        d, j = min(same) if same else (np.inf, None)
        row = {"effect": i, "kind": case["effects"][i]["kind"], "type": typ, "magnitude": mag,
               "detectable": truth["signal_chi2"][i] >= detectable_chi2, "chi2": truth["signal_chi2"][i],
               "distance_mm": d, "placed": d <= tol}
        if j is not None and d <= tol:
            used.add(j)
            r = reported[j]
            row["reported"] = r["magnitude"]
            row["reported_kind"] = r.get("kind", r.get("type"))
            row["sigma"] = r.get("uncertainty")
            if mag is None:
                row.update(sized=True, covered=None, covered_1sigma=None)
            else:
                row["sized"] = abs(r["magnitude"] / mag - 1.0) <= MAGNITUDE
                row["covered"] = _covered(r, mag)
                row["covered_1sigma"] = _covered(r, mag, 1.0)
        row["found"] = bool(row["placed"] and row.get("sized", False))
        rows.append(row)
    invented = [r for j, r in enumerate(reported) if j not in used and not any(
        judged_as(r) == typ and distance(r, g) <= 2 * (LINE_MM if typ in LINES else PLACE_MM)
        for _, typ, g, _ in atoms(case, E_board))]
    out = {"atoms": rows, "invented": [(r.get("type"), r.get("at_mm")) for r in invented],
           "n_reported": len(reported), "noise_only_case": not case["effects"]}
    if result:  # a diagnosis stopped by an error keeps what it had computed: no "after"
        out.update({k: result[k]["max_freq_error_pct"] for k in ("before", "parameters_only", "after") if k in result},
                   noise_only=result.get("noise_only"))
    return out
