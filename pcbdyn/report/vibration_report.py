"""What ``pcbdyn vibe`` shows: the parts table (worst margin first), the modes table, CSV files,
the board map coloured by margin, the response spectra, and the HTML page. Formatting only: the
numbers come from :func:`pcbdyn.vibration.assess`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..vibration.spectra import G
from .correlation_plots import draw_outline, shell_triangulation
from .files import PLOT, pyplot, save_figure, write_text


def parts_table(a) -> pd.DataFrame:
    """One row per part, worst margin first, units in the column names."""
    rows = []
    for p in a.parts:
        row = {
            "part": p.ref, "package": p.package, "c": p.c, "B [mm]": p.span_m * 1e3, "L [mm]": p.length_m * 1e3,
            "r": p.position_factor, "z_rms [mm]": p.z_rms_m * 1e3, "3 sigma [mm]": 3e3 * p.z_rms_m,
            "z_allow [mm]": p.z_allow_m * 1e3, "ratio": p.ratio, "margin [%]": 100.0 * p.margin,
            "nu0 [Hz]": p.rate_hz, "life [h]": np.inf if p.life_h is None else p.life_h,
            "a_rms [g]": p.accel_rms_g, "kappa_rms [1/m]": p.curvature_rms_per_m,
        }
        if a.duration is not None:
            row["damage (duration)"] = p.damage
        if a.sine is not None:
            row["sine z_peak [mm]"] = p.sine_z_peak_m * 1e3
            row["sine damage"] = p.sine_damage
        row["verdict"] = "ok" if p.ok else "FAILS"
        rows.append(row)
    return pd.DataFrame(rows)


def modes_table(a) -> pd.DataFrame:
    """One row per mode: frequency, damping, effective masses in percent (:func:`.modes.mass_columns`;
    none for a card judged inside its housing, whose modes are the system's)."""
    from .modes import mass_columns

    be = a.excitation
    masses = {} if a.effective_mass is None else mass_columns(a.effective_mass)
    return pd.DataFrame({"mode": np.arange(1, be.frequencies.size + 1), "frequency [Hz]": be.frequencies,
                         "damping ratio": be.zeta, "Q": 0.5 / be.zeta, **masses, "damping from": a.damping_source})


def modes_line(a) -> str:
    """How many modes the response sums, to where, and the share of the mass moved along the axis they carry."""
    be = a.excitation
    if a.effective_mass is None:
        return f"modes: {be.frequencies.size} of the system, up to {be.frequencies[-1]:.0f} Hz (static residual added)"
    return (f"modes: {be.frequencies.size} up to {be.frequencies[-1]:.0f} Hz, {100 * a.effective_mass.share(a.axis):.2f} "
            f"% of the mass moved along {a.axis} (static residual added for the rest)")


def format_table(df: pd.DataFrame) -> str:
    return df.to_string(index=False, float_format=lambda v: f"{v:.4g}")


def summary_lines(a) -> list:
    """Inputs and board-level results, one line each, for the terminal and the page."""
    lines = [f"input: {a.psd.name}, {a.input_grms:.2f} grms along {a.axis} ({a.psd.source})",
             f"damping: {a.damping.describe()}",
             modes_line(a),
             f"largest RMS relative displacement on the board: {a.z_peak_m * 1e3:.4g} mm"]
    if a.duration is not None:
        lines.append(f"duration: {a.duration:g} s per axis")
    if a.sine is not None:
        lines.append(f"sine sweep: {a.sine.name}, {a.sine.rate:g} octave/min, {a.sine.sweeps} sweep(s)")
    if a.octave is not None:
        o = a.octave
        lines.append(f"octave rule: board {o['board_hz']:.1f} Hz / chassis {o['chassis_hz']:.1f} Hz = "
                     f"{o['ratio']:.2f}: "
                     f"{'ok' if o['ok'] else 'FAILS'} ({o['rule']})")
    return lines + [f"note: {n}" for n in a.notes]


def margin_map(path, board, model, field_mm, field_label: str, parts, margin_label: str, title: str) -> None:
    """A response over the board (grey, ``field_mm`` per node) with each part's footprint coloured by
    its margin (red fails, green passes); ``parts`` have ``ref`` and ``margin``."""
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.patches import Polygon

    plt = pyplot()
    (x0, y0), (x1, y1) = board.outline.bbox
    fig, ax = plt.subplots(figsize=(7.5, float(np.clip(6.0 * (y1 - y0) / (x1 - x0), 3.0, 7.5)) + 2.0))
    draw_outline(ax, board.outline)
    cf = ax.tricontourf(shell_triangulation(model), np.nan_to_num(field_mm), levels=12, cmap="Greys", alpha=0.6)
    fig.colorbar(cf, ax=ax, fraction=0.046, pad=0.02, label=field_label)
    cmap, norm = plt.get_cmap("RdYlGn"), TwoSlopeNorm(vmin=-1.0, vcenter=0.0, vmax=1.0)
    corners = {c.ref: c.corners() for c in board.components}
    for p in parts:
        m = float(np.clip(p.margin, -1.0, 1.0))
        ax.add_patch(Polygon(corners[p.ref] * 1e3, closed=True, facecolor=cmap(norm(m)), edgecolor="k", alpha=0.9))
        x, y = corners[p.ref].mean(axis=0) * 1e3
        ax.text(x, y, f"{p.ref}\n{100 * p.margin:+.0f} %", ha="center", va="center", fontsize=8)
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, orientation="horizontal", fraction=0.05, pad=0.1, label=f"{margin_label} (clipped at +-100 %)")
    ax.set(aspect="equal", xlabel="x [mm]", ylabel="y [mm]")
    ax.set_title(title, fontsize=10)
    save_figure(fig, path, **PLOT)


def board_map(path, board, model, a) -> None:
    """RMS relative displacement over the board with each part coloured by its margin."""
    margin_map(path, board, model, a.node_z_rms * 1e3, "RMS relative displacement [mm]", a.parts,
               "margin z_allow / (3 z_rms) - 1",
               f"{board.name}: margin per part under {a.psd.name} ({a.input_grms:.1f} grms, {a.axis})")


def spectra_plot(path, a) -> None:
    """Input PSD and the absolute acceleration PSD at each part [g^2/Hz], log-log."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    f = a.grid
    ax.loglog(f, a.psd.at(f) / G**2, "k-", lw=2, label=f"input {a.psd.name} ({a.input_grms:.2f} grms)")
    for j, p in enumerate(a.parts):
        ax.loglog(f, a.part_accel_psd[:, j] / G**2, lw=1, label=f"{p.ref} ({p.accel_rms_g:.1f} grms)")
    for fr in a.excitation.frequencies[a.excitation.frequencies <= f[-1]]:
        ax.axvline(fr, color="0.85", lw=0.6, zorder=0)
    ax.set(xlabel="frequency [Hz]", ylabel="acceleration PSD [g^2/Hz]", title="response at the parts (modes in grey)")
    ax.legend(fontsize=7, ncol=2)
    ax.grid(True, which="both", alpha=0.3)
    save_figure(fig, path, **PLOT)


def spectra_csv(a) -> str:
    """Input PSD and, per part, the absolute acceleration and relative displacement PSDs."""
    cols = {"frequency [Hz]": a.grid, "input [g^2/Hz]": a.psd.at(a.grid) / G**2}
    for j, p in enumerate(a.parts):
        cols[f"{p.ref} acceleration [g^2/Hz]"] = a.part_accel_psd[:, j] / G**2
        cols[f"{p.ref} relative displacement [mm^2/Hz]"] = a.part_z_psd[:, j] * 1e6
    return pd.DataFrame(cols).to_csv(index=False, float_format="%.6g")


def write_outputs(out: Path, board, model, a) -> list:
    """parts.csv, modes.csv, response_psd.csv, board_map.png and response_psd.png; their names."""
    write_text(out / "parts.csv", parts_table(a).to_csv(index=False, float_format="%.6g"))
    write_text(out / "modes.csv", modes_table(a).to_csv(index=False, float_format="%.6g"))
    write_text(out / "response_psd.csv", spectra_csv(a))
    board_map(out / "board_map.png", board, model, a)
    spectra_plot(out / "response_psd.png", a)
    return ["parts.csv", "modes.csv", "response_psd.csv", "board_map.png", "response_psd.png"]


def verdict(parts, criterion: str) -> str:
    """'2 of 6 part(s) fail: U1, U3' or 'all 6 part(s) pass Steinberg's <criterion>'."""
    failing = [p.ref for p in parts if not p.ok]
    return f"{len(failing)} of {len(parts)} part(s) fail: {', '.join(failing)}" if failing else \
        f"all {len(parts)} part(s) pass Steinberg's {criterion}"


def verdict_page(command: str, board, board_toml, subtitle: str, inputs: dict, summary: list, parts_df, parts,
                 note: str):
    """The head of the page of ``vibe`` and ``shock``: title, inputs, summary and the parts table
    (rows coloured by verdict); the caller adds its pictures and tables and writes it."""
    from .html import Page, describe_file

    page = Page(f"pcbdyn {command}: {board.name}", subtitle=subtitle)
    page.items("Inputs", {"board": describe_file(board_toml), **inputs})
    page.text("Summary", summary)
    page.table("Parts, worst margin first", parts_df, status=["good" if p.ok else "bad" for p in parts], note=note)
    return page


def modes_section(page, board, a, table, model=None, config=None) -> None:
    """The modes ``table`` of the result ``a`` (``vibe``'s or ``shock``'s) on its page and, given the FE
    ``model`` of ``board`` (its configuration ``config``), an animated 3-D view of the modes used."""
    from .modes import MASS_NOTE
    from .view3d import shapes_view

    page.table("Modes", table, note=MASS_NOTE)
    be = a.excitation
    if model is not None and be.frequencies.size:
        page.view3d("Modes in 3-D", shapes_view(board.name, model, board.outlines(config), be.basis, [
            f"mode {k + 1}: {f:.1f} Hz, Q = {0.5 / z:.3g}" for k, (f, z) in enumerate(zip(be.frequencies, be.zeta))]))


def html_page(out: Path, board_toml, board, a, inputs: dict, model=None, config=None) -> Path:
    """report.html in ``out`` (after :func:`write_outputs`): verdicts, tables, pictures, inputs and the
    modes (:func:`modes_section`)."""
    page = verdict_page("vibe", board, board_toml,
                        f"{a.psd.name}, {a.input_grms:.2f} grms along {a.axis}: {verdict(a.parts, 'criterion')}",
                        inputs, summary_lines(a), parts_table(a), a.parts,
                        "z: RMS relative displacement normal to the board at the part's centre; z_allow: Steinberg's "
                        "allowable (2e7 reversals at 3 sigma) for a part where the board's displacement is measured; "
                        "r: Steinberg's position factor read from the model (z / largest z on the board); life: "
                        "three-band technique and Miner's rule at the zero up-crossing rate nu0.")
    page.pictures("Board map and response spectra", [out / "board_map.png", out / "response_psd.png"],
                  ["margin per part over the RMS relative displacement", "input and response acceleration PSDs"])
    modes_section(page, board, a, modes_table(a), model, config)
    return page.write(out / "report.html")
