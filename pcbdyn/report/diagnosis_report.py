"""Tables, the evidence map and the enriched board of ``pcbdyn diagnose`` (issue 7, step 6)."""

from __future__ import annotations

import numpy as np

#: SI unit of an effect -> (display unit, factor from SI)
DISPLAY = {"kg": ("g", 1e3), "kg*m^2": ("kg*mm^2", 1e6), "N/m": ("N/mm", 1e-3), "N*m/rad/m": ("N*m/rad/m", 1.0),
           "N*m^2": ("N*m^2", 1.0), "1": ("%", 100.0), "Pa": ("GPa", 1e-9)}


def shown(value: float, unit: str) -> tuple:
    """(value in the display unit, display unit)."""
    u, k = DISPLAY.get(unit, (unit, 1.0))
    return value * k, u


def two_sigma(e: dict) -> str:
    """An effect's 2-sigma interval in its unit shown (:func:`shown`): "lo to hi", or "lo or more" where the
    data leave it open above."""
    lo, hi = e["interval_2sigma"]
    a, _ = shown(lo, e["unit"])
    return f"{a:.3g} or more" if hi is None else f"{a:.3g} to {shown(hi, e['unit'])[0]:.3g}"


def format_effects(effects) -> str:
    """The effects as a table; on a structure of several plates with each effect's plate and its point in
    x, y, z."""
    if not effects:
        return "no effect found"
    plates = any("plate" in e for e in effects)
    plate_head, width = (f" {'plate':>8}", 24) if plates else ("", 18)
    rows = [f"{'type':>16} {'parameter':>16}{plate_head} {'at [mm]':>{width}} {'magnitude':>12} {'+-':>10} "
            f"{'2 sigma':>20} unit"]
    for e in effects:
        v, u = shown(e["magnitude"], e["unit"])
        s, _ = shown(e["uncertainty"], e["unit"])
        at = "(" + ", ".join(f"{c:.1f}" for c in e["at_mm"]) + ")"
        where = f" {e.get('plate', ''):>8}" if plates else ""
        rows.append(f"{e['type']:>16} {e['parameter']:>16}{where} {at:>{width}} {v:>12.4g} {s:>10.2g} "
                    f"{two_sigma(e):>20} {u}")
    return "\n".join(rows)


def format_states(before, params_only, after) -> str:
    """Per configuration and mode: frequency error [%] and MAC of the model as given, with the
    declared parameters fitted, and with the effects."""
    out = []
    for b, p, a in zip(before["configurations"], params_only["configurations"], after["configurations"]):
        out.append(f"[{b['configuration']}] max |df| [%]: as given {b['max_freq_error_pct']:.2f}, parameters only "
                   f"{p['max_freq_error_pct']:.2f}, with effects {a['max_freq_error_pct']:.2f}")
        out.append(f"{'mode':>5} {'f_test [Hz]':>12} {'df given':>9} {'df params':>9} {'df after':>9} "
                   f"{'MAC given':>9} {'MAC after':>9}")
        for qb, qp, qa in zip(b["modes"], p["modes"], a["modes"]):
            mac = "" if qb["mac"] is None else f"{qb['mac']:>9.3f} {qa['mac']:>9.3f}"
            out.append(f"{qb['test_mode']:>5} {qb['f_test_hz']:>12.2f} {qb['df_pct']:>+9.2f} {qp['df_pct']:>+9.2f} "
                       f"{qa['df_pct']:>+9.2f} {mac}")
    return "\n".join(out)


def summary(state) -> dict:
    """The JSON ``before``/``after`` entry."""
    return {"max_freq_error_pct": state["max_freq_error_pct"], "mean_mac": state["mean_mac"],
            "configurations": state["configurations"]}


def plot_evidence(path, board, evidence, effects) -> None:
    """Where the residual points: the chi^2 a point mass (and a ground spring) at each node would
    remove once the declared parameters are fitted, with the effects found marked."""
    from .files import PLOT, pyplot, save_figure
    from .labels import place_labels

    kinds = list(evidence)
    if getattr(board, "outline", None) is None:  # a structure in 3-D: 3-D maps
        from .pictures3d import point_map_3d

        fig = pyplot().figure(figsize=(6.5 * max(len(kinds), 1), 5.5))
        grid = fig.add_gridspec(1, max(len(kinds), 1))
        for k, kind in enumerate(kinds):
            xyz, gain = evidence[kind]
            ax = point_map_3d(fig, grid[0, k], xyz, gain, "chi^2 removed",
                              title=f"evidence for a {kind.replace('_', ' ')}")
            for e in effects:
                ax.scatter(*np.asarray(e["at_mm"], float)[:, None], marker="*", s=200, c="r", edgecolors="w")
        save_figure(fig, path, **PLOT)
        return
    fig, axes = pyplot().subplots(1, max(len(kinds), 1), figsize=(5.5 * max(len(kinds), 1), 5.0), squeeze=False,
                                layout="constrained")
    outline = np.vstack([board.outline.vertices, board.outline.vertices[:1]]) * 1e3
    for ax, kind in zip(axes[0], kinds):
        xy, gain = evidence[kind]
        ax.plot(outline[:, 0], outline[:, 1], "k-", lw=1)
        sc = ax.scatter(xy[:, 0] * 1e3, xy[:, 1] * 1e3, c=gain, s=18, cmap="viridis")
        fig.colorbar(sc, ax=ax, label="chi^2 removed")
        for e in effects:
            ax.plot(*e["at_mm"], "r*", ms=14, mec="w")
        ax.set(title=f"evidence for a {kind.replace('_', ' ')}", xlabel="x [mm]", ylabel="y [mm]", aspect="equal")
    for ax in axes[0][:len(kinds)]:
        place_labels(ax, [e["at_mm"] for e in effects], [e["type"] for e in effects], color="r")
    save_figure(fig, path, **PLOT)


def enriched_effects(diagnosis) -> list:
    """The effects in the form :func:`pcbdyn.board.enrich.write_enriched` takes (SI)."""
    out = []
    for e in diagnosis.effects:
        d = {"type": e["kind"], "name": e["name"], "value": e["magnitude"], "at": tuple(np.asarray(e["at_mm"]) / 1e3)}
        if "plate" in e:
            d["plate"] = e["plate"]
        if "section_height_mm" in e:
            d["height"] = 1e-3 * e["section_height_mm"]
        if "section_material" in e:
            d["material"] = e["section_material"]
        if "normal" in e:
            d["normal"] = e["normal"]
        for key in ("segment", "path", "polygon"):
            if f"{key}_mm" in e:
                d[key] = (np.asarray(e[f"{key}_mm"]) / 1e3).tolist()
        out.append(d)
    return out


def effect_outlines(effects) -> list:
    """The effects found as outlines for a 3-D view (kind "effect", labelled with their type and size):
    a point at ``at_mm``, or its path, segment or polygon; 2 coordinates on a board, 3 on a box."""
    out = []
    for e in effects:
        v, u = shown(e["magnitude"], e["unit"])
        key = next((k for k in ("path_mm", "segment_mm", "polygon_mm") if k in e), "at_mm")
        pts = np.asarray(e[key], float).reshape(-1, np.asarray(e["at_mm"]).size) / 1e3
        out.append({"kind": "effect", "label": f"{e['type']} {v:.3g} {u}", "closed": key == "polygon_mm",
                    "xy" if pts.shape[1] == 2 else "xyz": pts.tolist()})
    return out


def states_table(before, params_only, after):
    """Per configuration and test mode: frequency errors and MAC as given, with the parameters fitted and
    with the effects (the rows of :func:`format_states`)."""
    import pandas as pd

    rows = []
    for b, p, a in zip(before["configurations"], params_only["configurations"], after["configurations"]):
        for qb, qp, qa in zip(b["modes"], p["modes"], a["modes"]):
            rows.append({"configuration": b["configuration"], "test mode": qb["test_mode"],
                         "f_test [Hz]": qb["f_test_hz"], "df given [%]": qb["df_pct"],
                         "df parameters [%]": qp["df_pct"], "df with effects [%]": qa["df_pct"],
                         "MAC given": qb["mac"], "MAC with effects": qa["mac"]})
    return pd.DataFrame(rows)


def html_page(out, board_toml, board, d, shown_model, evidence_png=None):
    """report.html in ``out``: the effects found, the correlation before and after, an animated 3-D view of
    the modes of ``shown_model`` = (title, built model, modes, outlines) with the effects drawn on it, and
    the evidence map."""
    import pandas as pd

    from .html import Page, describe_file
    from .view3d import shapes_view

    page = Page(f"pcbdyn diagnose: {board.name}", subtitle=d.message)
    page.items("Inputs", {"board": describe_file(board_toml)})
    rows = []
    for e in d.effects:
        v, u = shown(e["magnitude"], e["unit"])
        s, _ = shown(e["uncertainty"], e["unit"])
        rows.append({"type": e["type"], "parameter": e["parameter"], "plate": e.get("plate", "-"),
                     "at [mm]": ", ".join(f"{c:.1f}" for c in e["at_mm"]), "magnitude": v, "+-": s,
                     "2 sigma": two_sigma(e), "unit": u})
    if rows:
        page.table("Effects found", pd.DataFrame(rows))
    else:
        page.text("Effects found", ["none: " + d.message])
    page.table("Correlation as given, with the parameters fitted, with the effects",
               states_table(d.before, d.parameters_only, d.after))
    title, built, modes, outlines = shown_model
    if modes.frequencies.size:
        page.view3d("Effects found, on the modes of the model", shapes_view(
            title, built.model, list(outlines) + effect_outlines(d.effects), modes.shapes,
            [f"mode {k + 1}: {f:.1f} Hz" for k, f in enumerate(modes.frequencies)]),
            note="red: the effects found, labelled with their size (hover over them)")
    if evidence_png is not None:
        page.pictures("Evidence", [evidence_png], ["chi^2 a point effect at each node would remove"])
    return page.write(out / "report.html")
