"""``pcbdyn vibe board.toml --psd spec.csv|NAME``: does the board survive its vibration
specification? Random (and sine) response through the board's fixtures, Steinberg's check and
fatigue life of every part, the octave rule; tables, CSV, pictures, JSON and an HTML page."""

from __future__ import annotations

from pathlib import Path

import click

from .common import PROBE_TOL, done, fail, folder_outputs, library_option, solve_structure, step, units_option

#: at most this many modes are computed (all of them up to twice the top input frequency otherwise)
MAX_MODES = 150
#: at least this many, whatever the band (a spectrum below the fundamental still needs them)
MIN_MODES = 3


@click.command("vibe")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--psd", "psd_text", required=True,
              help="input acceleration PSD: a CSV with columns 'frequency [Hz]', 'psd [g^2/Hz]', or a bundled "
                   "name (gevs-qual, gevs-accept, gevs-workmanship)")
@click.option("--sine", "sine_csv", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="sine sweep: a CSV with 'frequency [Hz]' and the peak 'amplitude [g]' (or '[mm]' of displacement)")
@click.option("--sweep-rate", type=float, default=2.0, show_default=True, help="sine sweep rate [octave/min]")
@click.option("--sweeps", type=click.IntRange(min=1), default=1, show_default=True, help="sine sweeps through the band")
@click.option("--damping", "damping_text", default="steinberg", show_default=True,
              help="'steinberg' (Q = sqrt(f_n)), 'zeta=0.05', 'Q=10', or a UFF file whose identified damping goes to "
                   "the model modes it pairs with")
@click.option("--duration", default=None,
              help="test time per axis, e.g. '120 s' (default: the time the bundled specification states)")
@click.option("--axis", type=click.Choice(["x", "y", "z"]), default="z", show_default=True, help="excitation axis")
@click.option("--chassis-freq", default=None, help="the chassis resonance, e.g. '80 Hz': checks the octave rule")
@click.option("--config", default=None, help="configuration name from [[configurations]]")
@click.option("--exclude", multiple=True, help="a part reference to leave out of Steinberg's check (repeatable)")
@folder_outputs("folder for parts.csv, modes.csv, response_psd.csv, board_map.png, response_psd.png",
                "write input_grms, modes[] and parts[] (ref, z_rms_m, z_allow_m, ratio, life_h, ...) as JSON", html=True)
@library_option()
@units_option
def command(board_toml, psd_text, sine_csv, sweep_rate, sweeps, damping_text, duration, axis, chassis_freq, config,
            exclude, out, json_path, html):
    """Judge a board under a random (and sine) vibration specification: RMS responses at every part,
    Steinberg's allowable displacement, fatigue life (three-band, Miner) and the octave rule."""
    from ..board import load_board
    from ..domain import StructureError
    from ..fe import ModelError
    from ..problems import load_structure
    from ..report import vibration_report as report
    from ..testdata import TestDataError
    from ..units import UnitError, to_si
    from ..vibration import (VibrationError, analysis_band, assess, judged_parts, load_psd, parse_damping,
                             read_sine_csv)

    try:
        board = load_structure(board_toml)
        psd = load_psd(psd_text)
        sine = read_sine_csv(sine_csv, sweep_rate, sweeps) if sine_csv is not None else None
        damping = parse_damping(damping_text)
        seconds = to_si(duration, "s", "--duration") if duration is not None else psd.duration
        chassis = to_si(chassis_freq, "Hz", "--chassis-freq") if chassis_freq is not None else None
        if getattr(board, "cards", None):
            return _system(board, board_toml, psd, sine, damping, seconds, axis, chassis, config, exclude, out,
                           json_path, html)
        if not hasattr(board, "components"):  # a box without cards: the board reader says what vibe takes
            board = load_board(board_toml)
        parts = judged_parts(board, exclude)
        bm, modes, K, M = solve_structure(board, config, n_modes=MAX_MODES, f_max=analysis_band(psd, sine),
                                          min_modes=MIN_MODES)
        t0 = step(f"random response of {len(parts)} part(s) to {psd.name} along {axis}")
        a = assess(board, bm, modes, K, M, psd, damping, axis=axis, duration=seconds, sine=sine, chassis_hz=chassis,
                   parts=parts, probe_tol=PROBE_TOL)
        done(t0)
    except (StructureError, ModelError, TestDataError, UnitError, VibrationError) as exc:
        fail(str(exc))
    inputs = {"configuration": config or "base", "PSD": f"{psd_text} ({psd.source})",
              "sine sweep": str(sine_csv) if sine_csv else None, "damping": damping.describe(),
              "axis": axis, "duration": None if seconds is None else f"{seconds:g} s",
              "chassis frequency": None if chassis is None else f"{chassis:g} Hz",
              "excluded parts": ", ".join(exclude) or None}
    report_verdict("vibe", report, a, board_toml, board, bm.model, psd.name, inputs, out, json_path, html, config)


def report_verdict(name: str, report, result, board_toml, board, model, input_name: str, inputs: dict, out, json_path,
                   html: bool, config=None) -> None:
    """The end of ``vibe`` and ``shock``: print the summary and the parts table of ``result`` (through
    its ``report`` module), write its files into ``out`` (the page with ``html``, the manifest) and
    the JSON, with the files written."""
    click.echo(f"\n{board.name} [{inputs['configuration']}] under {input_name}:")
    click.echo("\n".join(report.summary_lines(result)))
    click.echo("\n" + report.format_table(report.parts_table(result)))
    written = []
    if out is not None:
        from ..report.manifest import replacing

        t0 = step(f"writing tables and pictures to {out}")
        with replacing(out, f"pcbdyn {name}") as run:  # the earlier --out stays whole until all is written
            written = report.write_outputs(run.path, board, model, result)
            if html:
                written.append(report.html_page(run.path, board_toml, board, result, inputs, model, config).name)
        done(t0)
        click.echo(f"results written to {out}/ ({len(written)} files)", err=True)
    if json_path is not None:
        from ..report.files import write_json

        write_json(json_path, {"board": board.name, "configuration": inputs["configuration"], **result.to_dict(),
                               "files": written})


def _system(box, box_toml, psd, sine, damping, seconds, axis, chassis, config, exclude, out, json_path, html):
    """vibe on a box with its cards: shaken at the housing's supports, every card's parts judged
    (:func:`pcbdyn.vibration.system.assess_system`); per card, the tables and pictures in ``out/<card>/``."""
    from ..report import vibration_report as report
    from ..report.files import write_json
    from ..vibration import analysis_band
    from ..vibration.system import assess_system, card_parts

    system, modes, K, M = solve_structure(box, config, n_modes=MAX_MODES, f_max=analysis_band(psd, sine),
                                          min_modes=MIN_MODES)
    t0 = step(f"random response of {len(system.cards)} card(s) to {psd.name} along {axis}")
    a = assess_system(system, modes, K, M, psd, damping, axis=axis, duration=seconds, sine=sine, chassis_hz=chassis,
                      parts=card_parts(system, exclude), probe_tol=PROBE_TOL)
    done(t0)
    source = "stated" if a.stated else "computed: the first mode mostly the housing's"
    click.echo(f"\n{box.name} [{config or 'base'}] under {psd.name}, shaken at the housing's supports along {axis}; "
               f"chassis resonance {'none found' if a.chassis_hz is None else f'{a.chassis_hz:.1f} Hz'} ({source})")
    for name, ca in a.cards.items():
        click.echo(f"\ncard {name} ({system.cards[name].card.board.path.name}):")
        click.echo("\n".join(report.summary_lines(ca)))
        click.echo("\n" + report.format_table(report.parts_table(ca)))
    if html:
        click.echo("note: --html is written for a board; a system's results are the tables and pictures per card",
                   err=True)
    written = []
    if out is not None:
        from ..report.manifest import replacing

        with replacing(out, "pcbdyn vibe") as run:  # the earlier --out stays whole until all is written
            for name, ca in a.cards.items():
                pc = system.cards[name]
                written += [f"{name}/{w}" for w in report.write_outputs(run.path / name, pc.card.board,
                                                                          pc.local.model, ca)]
        click.echo(f"results written to {out}/ ({len(written)} files)", err=True)
    if json_path is not None:
        write_json(json_path, {"box": box.name, "configuration": config or "base", **a.to_dict(), "files": written})
