"""What ``pcbdyn shock`` shows: the parts table (worst margin first), the modes table, the SRS of the
input with its pseudo-velocity, CSV files, the board map coloured by margin, and the HTML page.
Formatting only: the numbers come from :func:`pcbdyn.vibration.shock.assess_shock`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..vibration.spectra import G
from ..vibration.srs import PV_SEVERE, pseudo_velocity
from .files import PLOT, pyplot, save_figure, write_text
from .vibration_report import format_table, margin_map, modes_line, modes_section, verdict, verdict_page
from .vibration_report import modes_table as vibration_modes_table

__all__ = ["format_table", "html_page", "parts_table", "summary_lines", "write_outputs"]

INCH = 0.0254


def _ms(t):
    return None if t is None else t * 1e3


def parts_table(s) -> pd.DataFrame:
    """One row per part, worst margin first, units in the column names (no times for an SRS input)."""
    timed = s.combination is None
    rows = []
    for p in s.parts:
        row = {"part": p.ref, "package": p.package, "c": p.c, "B [mm]": p.span_m * 1e3, "L [mm]": p.length_m * 1e3,
               "r": p.position_factor, "z_peak [mm]": p.z_peak_m * 1e3}
        if timed:
            row["t_z [ms]"] = _ms(p.t_peak_s)
        row.update({"z_allow [mm]": p.z_allow_m * 1e3, "ratio": p.ratio, "margin [%]": 100.0 * p.margin,
                    "a_peak [g]": p.accel_peak_g})
        if timed:
            row["t_a [ms]"] = _ms(p.t_accel_s)
        row["kappa_peak [1/m]"] = p.curvature_peak_1pm
        if timed:
            row["t_kappa [ms]"] = _ms(p.t_curvature_s)
        row["verdict"] = "ok" if p.ok else "FAILS"
        rows.append(row)
    return pd.DataFrame(rows)


def modes_table(s) -> pd.DataFrame:
    """vibe's modes table with each mode's participation factor."""
    df = vibration_modes_table(s)
    df.insert(4, "participation [kg^0.5]", s.excitation.gamma)
    return df


def srs_table(s) -> pd.DataFrame:
    pv = pseudo_velocity(s.srs_f, s.srs_value)
    return pd.DataFrame({"frequency [Hz]": s.srs_f, "srs [g]": s.srs_value / G, "pseudo velocity [m/s]": pv,
                         "pseudo velocity [in/s]": pv / INCH})


def summary_lines(s) -> list:
    """Inputs and board-level results, one line each, for the terminal and the page."""
    inp = s.input
    lines = [f"input: {inp.describe()}, along {s.axis}",
             f"damping: {s.damping.describe()}",
             modes_line(s)]
    if s.combination is not None:
        lines.append(f"modal peaks combined by {s.combination.upper()} (the modes left out: the zero-period "
                     "acceleration, statically)")
    else:
        lines.append("modal transient response, integrated exactly for the piecewise-linear input, static residual "
                     "for the modes left out")
    pv = pseudo_velocity(s.srs_f, s.srs_value)
    k = int(np.argmax(pv))
    lines += [f"largest peak relative displacement on the board: {s.z_peak_m * 1e3:.4g} mm",
              f"SRS (Q = {s.srs_q:g}): largest {s.srs_value.max() / G:.4g} g; pseudo-velocity up to {pv[k]:.3g} m/s "
              f"({pv[k] / INCH:.3g} in/s) at {s.srs_f[k]:.4g} Hz, "
              + ("above" if pv[k] > PV_SEVERE else "below") + " the 100 in/s severity line"]
    return lines + [f"note: {n}" for n in s.notes]


def srs_plot(path, s) -> None:
    """The SRS [g] and its pseudo-velocity [m/s] with the 100 in/s line, log-log, modes in grey."""
    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11.0, 4.6))
    pv = pseudo_velocity(s.srs_f, s.srs_value)
    what = "specification" if s.combination is not None else "maximax absolute acceleration"
    ax1.loglog(s.srs_f, s.srs_value / G, "k-", lw=1.8, label=f"{what}, Q = {s.srs_q:g}")
    ax2.loglog(s.srs_f, pv, "k-", lw=1.8, label="pseudo-velocity")
    ax2.axhline(PV_SEVERE, color="r", ls="--", lw=1.2, label="100 in/s (2.54 m/s)")
    for ax in (ax1, ax2):
        for fr in s.excitation.frequencies[s.excitation.frequencies <= s.srs_f[-1]]:
            ax.axvline(fr, color="0.85", lw=0.6, zorder=0)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    ax1.set(xlabel="frequency [Hz]", ylabel="SRS [g]", title=f"shock response spectrum: {s.input.name}")
    ax2.set(xlabel="frequency [Hz]", ylabel="pseudo-velocity [m/s]", title="pseudo-velocity (board modes in grey)")
    save_figure(fig, path, **PLOT)


def write_outputs(out: Path, board, model, s) -> list:
    """parts.csv, modes.csv, srs.csv, board_map.png and srs.png; their names."""
    write_text(out / "parts.csv", parts_table(s).to_csv(index=False, float_format="%.6g"))
    write_text(out / "modes.csv", modes_table(s).to_csv(index=False, float_format="%.6g"))
    write_text(out / "srs.csv", srs_table(s).to_csv(index=False, float_format="%.6g"))
    margin_map(out / "board_map.png", board, model, s.node_z_peak * 1e3, "peak relative displacement [mm]", s.parts,
               "margin z_allow / z_peak - 1", f"{board.name}: margin per part under {s.input.name} ({s.axis})")
    srs_plot(out / "srs.png", s)
    return ["parts.csv", "modes.csv", "srs.csv", "board_map.png", "srs.png"]


def html_page(out: Path, board_toml, board, s, inputs: dict, model=None, config=None) -> Path:
    """report.html in ``out`` (after :func:`write_outputs`): verdicts, tables, pictures, inputs and the
    modes (:func:`.vibration_report.modes_section`)."""
    page = verdict_page("shock", board, board_toml, f"{s.input.name} along {s.axis}: {verdict(s.parts, 'shock criterion')}",
                        inputs, summary_lines(s), parts_table(s), s.parts,
                        "z: peak relative displacement normal to the board at the part's centre; z_allow: Steinberg's "
                        "shock allowable (six times his vibration allowable) for a part where the board's displacement "
                        "is measured; ratio z / z_allow; r: position factor read from the model (z / largest z on the "
                        "board); a: peak absolute acceleration along the axis; kappa: peak curvature along or across "
                        "the part, averaged over its footprint; t: time of each peak.")
    page.pictures("Board map and shock response spectrum", [out / "board_map.png", out / "srs.png"],
                  ["margin per part over the peak relative displacement", "SRS and pseudo-velocity"])
    page.table("Shock response spectrum", srs_table(s))
    modes_section(page, board, s, modes_table(s), model, config)
    return page.write(out / "report.html")
