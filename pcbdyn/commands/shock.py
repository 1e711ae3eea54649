"""``pcbdyn shock board.toml --pulse "half-sine 1500 g 0.5 ms" | --history accel.csv | --srs spec.csv``:
does the board survive its shock? Modal transient response through the fixtures (or combined modal
peaks under an SRS), peak displacement, acceleration and curvature at every part with Steinberg's
shock allowable, the SRS of the input and its pseudo-velocity; tables, CSV, pictures, JSON, HTML."""

from __future__ import annotations

from pathlib import Path

import click

from .common import PROBE_TOL, done, folder_outputs, input_errors, library_option, number_pair, solve_structure, step
from .vibe import MAX_MODES, MIN_MODES, report_verdict

_FILE = click.Path(exists=True, dir_okay=False, path_type=Path)


@click.command("shock")
@click.argument("board_toml", type=_FILE)
@click.option("--pulse", "pulse_text", default=None,
              help="a classical pulse with units: 'half-sine 1500 g 0.5 ms', 'sawtooth 100 g 6 ms' (terminal peak), "
                   "'trapezoid 50 g 11 ms rise 1 ms fall 1 ms'")
@click.option("--history", "history_csv", type=_FILE, default=None,
              help="an acceleration record: a CSV with columns 'time [s]' and 'acceleration [g]' (any units of those "
                   "kinds), read as straight lines between samples and zero after the last")
@click.option("--srs", "srs_csv", type=_FILE, default=None,
              help="a shock response spectrum to meet: a CSV with 'frequency [Hz]' and 'acceleration [g]' (log-log "
                   "between breakpoints)")
@click.option("--combine", "combination", type=click.Choice(["srss", "abs", "nrl"]), default="srss", show_default=True,
              help="how the modal peaks under --srs are combined (square root of the sum of squares, absolute sum, NRL)")
@click.option("--damping", "damping_text", default="steinberg", show_default=True,
              help="the board's modal damping: 'steinberg' (Q = sqrt(f_n)), 'zeta=0.05', 'Q=10', or a UFF file whose "
                   "identified damping goes to the model modes it pairs with")
@click.option("--srs-q", type=click.FloatRange(min=0.5, min_open=True), default=10.0, show_default=True,
              help="quality factor of the shock response spectrum (of the input, or the one --srs was written for)")
@click.option("--srs-band", default="10,10000", show_default=True,
              help="frequencies [Hz] over which the input's SRS is computed, at 1/12-octave points")
@click.option("--axis", type=click.Choice(["x", "y", "z"]), default="z", show_default=True, help="shock axis")
@click.option("--config", default=None, help="configuration name from [[configurations]]")
@click.option("--exclude", multiple=True, help="a part reference to leave out of Steinberg's check (repeatable)")
@folder_outputs("folder for parts.csv, modes.csv, srs.csv, board_map.png, srs.png",
                "write input, modes[], parts[] (ref, z_peak_m, curvature_peak_1pm, z_allow_m, ratio, t_peak_s, ...) "
                "and srs (frequency, value) as JSON", html=True)
@library_option()
def command(board_toml, pulse_text, history_csv, srs_csv, combination, damping_text, srs_q, srs_band, axis, config,
            exclude, out, json_path, html):
    """Judge a board under a shock pulse, an acceleration record or a shock response spectrum: peak
    responses at every part against Steinberg's shock allowable, and the SRS of the input."""
    from ..board import load_board
    from ..report import shock_report as report
    from ..vibration import VibrationError, judged_parts, parse_damping
    from ..vibration.pulses import parse_pulse, read_history, read_srs
    from ..vibration.shock import analysis_band, assess_shock
    from ..vibration.srs import octave_points

    given = [x for x in (pulse_text, history_csv, srs_csv) if x is not None]
    if len(given) != 1:
        raise click.UsageError("give exactly one of --pulse, --history and --srs")
    band = number_pair(srs_band, "--srs-band", "Hz")
    with input_errors(VibrationError):
        octave_points(*band)  # a bad band is said before any work
        board = load_board(board_toml)
        inp = parse_pulse(pulse_text) if pulse_text else read_history(history_csv) if history_csv else \
            read_srs(srs_csv, srs_q)
        damping = parse_damping(damping_text)
        parts = judged_parts(board, exclude)
        bm, modes, K, M = solve_structure(board, config, n_modes=MAX_MODES, f_max=analysis_band(inp), min_modes=MIN_MODES)
        t0 = step(f"shock response of {len(parts)} part(s) to {inp.name} along {axis}")
        s = assess_shock(board, bm, modes, K, M, inp, damping, axis=axis, parts=parts, combination=combination,
                         srs_band=band, srs_q=srs_q, probe_tol=PROBE_TOL)
        done(t0)
    inputs = {"configuration": config or "base", "input": inp.describe(), "damping": damping.describe(),
              "axis": axis, "SRS": f"Q = {s.srs_q:g}, {s.srs_f[0]:g}-{s.srs_f[-1]:.5g} Hz at 1/12 octave",
              "combination": s.combination.upper() if s.combination else None,
              "excluded parts": ", ".join(exclude) or None}
    report_verdict("shock", report, s, board_toml, board, bm.model, inp.name, inputs, out, json_path, html, config)
