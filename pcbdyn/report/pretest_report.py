"""What ``pcbdyn pretest`` writes: the JSON (its keys named in issue 41 are a contract), the terminal
summary, the candidate and sensor CSVs, a map of the choices and the HTML page. Formatting only: the
choices come from :mod:`pcbdyn.problems.pretest` and :mod:`pcbdyn.problems.pretest_configs`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .files import save_figure, write_text


def _where(cand, i: int, box: bool) -> dict:
    x = cand.xyz[i] * 1e3
    out = {"id": int(cand.ids[i]), "x_mm": float(x[0]), "y_mm": float(x[1])}
    if box:
        out.update({"z_mm": float(x[2]), "plate": cand.plate[i]})
    return out


def pretest_json(structure, model, cand, source: dict, sensors, loading, exciter, suspension, designed,
                 entries, box: bool) -> dict:
    """The result as JSON-ready data (see the module docstring)."""
    triaxial = len(sensors.codes) > len(sensors.chosen)
    data = {
        "structure": structure.name, "file": str(structure.path),
        "target_modes_hz": model.frequencies.tolist(),
        "candidates": {**source, "count": len(cand), "usable": int(cand.usable.sum())},
        "sensors": [{**_where(cand, i, box), "direction": "xyz" if triaxial else sensors.codes[k]}
                    for k, i in enumerate(sensors.chosen)],
        "automac_max_offdiag": sensors.result.automac_max,
        "fisher_log_det": sensors.result.log_det, "efi_log_det": sensors.result.efi_log_det,
        "mass_loading": {"sensor_mass_kg": loading["sensor_mass_kg"],
                         "first_order_pct": loading["first_order_pct"].tolist(),
                         "shift_pct": loading["shift_pct"].tolist()},
        "exciter": {**_where(cand, exciter["index"], box), "direction": exciter["direction"],
                    "share_per_mode": exciter["share"].tolist(), "min_share": float(exciter["share"].min()),
                    "required_share": exciter["required_share"],
                    "meets_required_share": bool(exciter["share"].min() >= exciter["required_share"])},
    }
    if suspension is not None:
        first = float(np.sqrt(model.low_lam[0]) / (2 * np.pi))
        data["suspension"] = {
            "points": [_where(cand, i, box) for i in suspension.chosen], "direction": "+z",
            "stiffness_n_per_m": suspension.k, "suspension_hz": suspension.solved_hz.tolist(),
            "predicted_suspension_hz": suspension.predicted_hz.tolist(),
            "first_elastic_hz": first,
            "suspension_share_of_first_elastic": float(suspension.solved_hz.max() / first),
            "elastic_hz_with_springs": suspension.elastic_hz.tolist(),
            "elastic_shift_max_pct": float(np.max(np.abs(suspension.shift_pct(model.frequencies))))}
    data["configurations"] = entries
    if designed is not None:
        data["identifiability"] = {"before": designed.before, "after": designed.after,
                                   "candidates_weighed": designed.candidates}
        if designed.existing is not None:
            data["identifiability"]["existing"] = designed.existing
    return data


def summary(data: dict) -> str:
    """The terminal report of :func:`pretest_json`'s data."""
    f = ", ".join(f"{v:.1f}" for v in data["target_modes_hz"])
    lines = [f"{data['structure']}: {len(data['target_modes_hz'])} target modes ({f} Hz); "
             f"{data['candidates']['usable']} of {data['candidates']['count']} candidate points usable"]
    s = data["sensors"]
    lines.append(f"sensors: {len(s)} ({', '.join(sorted({q['direction'] for q in s}))}), log det(Phi^T Phi) "
                 f"{data['fisher_log_det']:.2f} (EfI alone {data['efi_log_det']:.2f}), largest off-diagonal AutoMAC "
                 f"{data['automac_max_offdiag']:.3f}")
    ml = data["mass_loading"]
    lines.append(f"mass loading of {ml['sensor_mass_kg'] * 1e3:g} g sensors: frequency shifts "
                 + ", ".join(f"{v:+.2f}" for v in ml["shift_pct"]) + " %"
                 + ("; more than 1 %: lighter sensors, fewer, or a laser vibrometer"
                    if max(abs(v) for v in ml["shift_pct"]) > 1.0 else ""))
    e = data["exciter"]
    lines.append(f"exciter: point {e['id']} ({e['x_mm']:.1f}, {e['y_mm']:.1f}"
                 + (f", {e['z_mm']:.1f}" if "z_mm" in e else "") + f" mm) along {e['direction']}, every target mode "
                 f"driven at >= {100 * e['min_share']:.0f} % of its best point"
                 + ("" if e["meets_required_share"] else f", below the {100 * e['required_share']:g} % asked for: no "
                    "single point drives every target mode; excite at two points, or split the band"))
    if "suspension" in data:
        sp = data["suspension"]
        pts = "; ".join(f"({p['x_mm']:.1f}, {p['y_mm']:.1f})" for p in sp["points"])
        lines.append(f"suspension: springs along z of {sp['stiffness_n_per_m']:.4g} N/m at {pts} mm: suspension modes "
                     f"up to {max(sp['suspension_hz']):.2f} Hz ({100 * sp['suspension_share_of_first_elastic']:.1f} % "
                     f"of the first elastic mode), elastic modes shifted <= {sp['elastic_shift_max_pct']:.3f} %")
    if "identifiability" in data:
        idf, designed = data["identifiability"], bool(data["configurations"])
        lines.append("parameter      1-sigma [%]: base test" + ("   with own configs" if "existing" in idf else "")
                     + ("   with designed" if designed else ""))
        for name, before in idf["before"]["std_pct"].items():
            own = f"   {idf['existing']['std_pct'][name]:17.3g}" if "existing" in idf else ""
            after = f"   {idf['after']['std_pct'][name]:13.3g}" if designed else ""
            lines.append(f"  {name:<24} {before:10.3g}{own}{after}")
        lines.append(f"  condition number          {idf['before']['condition']:10.3g}"
                     + (f"   {idf['existing']['condition']:17.3g}" if "existing" in idf else "")
                     + (f"   {idf['after']['condition']:13.3g}" if designed else ""))
        for c in data["configurations"]:
            m = c["masses"][0]
            lines.append(f"  [[configurations]] {c['name']}: {m['mass_kg'] * 1e3:g} g at "
                         f"({', '.join(f'{v:.1f}' for v in m['at_mm'])}) mm" + (f" on {m['plate']}" if "plate" in m
                                                                                  else ""))
    return "\n".join(lines)


def write_candidates_csv(path, cand) -> None:
    """``point,x [mm],y [mm],z [mm],plate,on_part``: every candidate, the part covering it flagged."""
    rows = ["point,x [mm],y [mm],z [mm],plate,on_part"]
    rows += [f"{int(i)},{x[0]:.6g},{x[1]:.6g},{x[2]:.6g},{plate or ''},{part}"
             for i, x, plate, part in zip(cand.ids, cand.xyz * 1e3, cand.plate, cand.on_part)]
    write_text(path, "\n".join(rows) + "\n")


def write_sensor_points(path, cand, sensors) -> None:
    """The chosen sensors as a points.csv (``point,x [mm],y [mm],z [mm],dir``, one row per measured
    direction) for ``simulate-test`` and ``correlate``."""
    rows = ["point,x [mm],y [mm],z [mm],dir"]
    for i, code in zip(sensors.point, sensors.codes):
        x = cand.xyz[i] * 1e3
        rows.append(f"{int(cand.ids[i])},{x[0]:.6g},{x[1]:.6g},{x[2]:.6g},{code}")
    write_text(path, "\n".join(rows) + "\n")


def pretest_map(path, cand, data: dict, box: bool) -> Path:
    """A picture of the candidates (flagged ones grey), sensors, exciter, suspension points and added masses."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(8, 6))
    ax = fig.add_subplot(projection="3d" if box else None)
    dims = 3 if box else 2

    def put(xyz, **kw):
        xyz = np.atleast_2d(np.asarray(xyz, float))
        if xyz.size:
            ax.scatter(*xyz[:, :dims].T, **kw)

    put(cand.xyz[cand.usable] * 1e3, s=8, c="lightgray", label="candidates")
    put(cand.xyz[~cand.usable] * 1e3, s=8, c="gray", marker="x", label="on a part")
    put([[s["x_mm"], s["y_mm"], s.get("z_mm", 0.0)] for s in data["sensors"]], s=50, c="tab:blue", label="sensors")
    e = data["exciter"]
    put([[e["x_mm"], e["y_mm"], e.get("z_mm", 0.0)]], s=120, c="tab:red", marker="*", label="exciter")
    if "suspension" in data:
        put([[p["x_mm"], p["y_mm"], p.get("z_mm", 0.0)] for p in data["suspension"]["points"]], s=70, c="tab:green",
            marker="^", label="suspension")
    at = [m["at_mm"] for c in data["configurations"] for m in c["masses"]]
    if at and not box:
        put(at, s=90, c="tab:orange", marker="s", label="added masses")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    if not box:
        ax.set_aspect("equal")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7)
    ax.set_title(f"pretest: {data['structure']}")
    return save_figure(fig, path, bbox_inches="tight")


def pretest_page(out: Path, toml_path, data: dict, written: list) -> Path:
    """report.html in ``out``: the summary's tables and the map."""
    import pandas as pd

    from .html import Page, describe_file

    page = Page(f"pcbdyn pretest: {data['structure']}",
                subtitle=f"{len(data['sensors'])} sensors, AutoMAC <= {data['automac_max_offdiag']:.3f}")
    page.items("Inputs", {"structure": describe_file(toml_path), "candidates": str(data["candidates"])})
    page.table("Sensors", pd.DataFrame(data["sensors"]))
    page.items("Exciter", {k: v for k, v in data["exciter"].items() if k != "share_per_mode"})
    if "suspension" in data:
        page.items("Suspension", {k: v for k, v in data["suspension"].items() if k != "points"})
    if "identifiability" in data:
        idf = data["identifiability"]
        rows = [{"parameter": n, "base test [%]": v, **({"with own configurations [%]": idf["existing"]["std_pct"][n]}
                                                         if "existing" in idf else {}),
                 **({"with designed [%]": idf["after"]["std_pct"][n]} if data["configurations"] else {})}
                for n, v in idf["before"]["std_pct"].items()]
        page.table("Predicted 1-sigma of each parameter", pd.DataFrame(rows),
                   note="frequency equations with the stated noise, linear at the starting values")
    pngs = [out / n for n in written if n.endswith(".png")]
    if pngs:
        page.pictures("Map", pngs, [Path(p).stem for p in pngs])
    return page.write(out / "report.html")
