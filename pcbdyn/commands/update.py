"""``pcbdyn update board.toml test.uff [c2=test2.uff ...]``: sensitivity-based updating of the board's
[[parameters]] against one or more test configurations (thesis ch. 3, 4, 6): parameter table,
before/after correlation, iteration plots, board.updated.toml and JSON.

With ``--frequencies FILE.csv`` (columns configuration, mode, frequency_hz; configuration c1 or
base = the base configuration, other names = [[configurations]]) only frequencies are used
(method freq) and test mode n is paired with elastic model mode n (pairing by order).
With UFF shapes, pairing is by MAC; QMS/FBM equations are built per measured mode on the model
condensed dynamically onto the measured DOFs at that mode's frequency (see
:meth:`pcbdyn.problems.UpdateProblem.mode_configurations`); the before/after tables
always come from full-model solves.

FRF methods (frf-in: excitation residual, eq. 3.34; frf-out: receptance residual, eq. 3.35;
frf-direct: eq. 3.40) read the FRFs of each UFF file (any kind; converted to receptance), excite
the model DOF under the reference point (it must be on a mesh node and, for frf-in/frf-out, among
the responses: a driving-point FRF, since the equations are written on the model condensed
exactly onto the measured DOFs at each line) and use the updating
frequencies of ``--frf-freqs`` or, by default, lines away from the resonances where test and
model FRFs correlate (FDAC, see :func:`pcbdyn.updating.frf_lines.choose_frf_frequencies`).
The before/after tables pair the file's modes (dataset 55) with the model by MAC; a file without
modes is checked against its FRF peaks, paired by order. Damped data: frf-in with
``--damping diagonal|proportional|light`` or frf-direct; frf-out assumes little damping.

The modal methods run :func:`pcbdyn.problems.fit.fit`: frequencies in units of the test noise
(``--noise``, 0.2 % assumed) and of the model's mesh error (the model on a mesh twice as fine at the fitted
parameters; ``--no-mesh-check`` skips it), log-scale and wide parameters scanned first, the shapes joining
the objective where the frequencies leave a parameter open, a trust region, and the verdict: converged, on
a bound, not determined (with the direction), or the model cannot fit the test (chi^2 against its degrees
of freedom). A fit that did not converge writes no updated board unless ``--force``.
"""

from __future__ import annotations

import click

from .common import (done, echo_verdict, fail, folder_outputs, input_errors, library_option, measured_configurations,
                     parse_extra, parse_noise, result_path, step, test_arguments, units_option)

def parse_frf_freqs(text) -> list:
    """'150,230 Hz' or '150,230' -> frequencies [Hz]."""
    try:
        vals = [float(v) for v in text.replace("Hz", "").split(",") if v.strip()]
    except ValueError:
        raise click.BadParameter(f"'{text}' is not a comma-separated list of frequencies in Hz (e.g. 150,230,410)",
                                 param_hint="--frf-freqs") from None
    if not vals or min(vals) <= 0:
        raise click.BadParameter(f"'{text}': give positive frequencies in Hz (e.g. 150,230,410)", param_hint="--frf-freqs")
    return vals


@click.command("update")
@test_arguments
@click.option("--method", type=click.Choice(["freq", "fbm", "qms", "frf-in", "frf-out", "frf-direct"]),
              default="freq", show_default=True)
@click.option("--frf-freqs", default=None,
              help="FRF methods: updating frequencies in Hz, e.g. '150,230,410' (default: chosen automatically "
                   "away from resonances where the FDAC of test and model is high)")
@click.option("--damping", type=click.Choice(["undamped", "proportional", "diagonal", "light"]), default="undamped",
              show_default=True, help="FRF methods: treatment of the unknown damping in the data (thesis appendix A); "
                                      "frf-out takes undamped or proportional, frf-direct undamped")
@click.option("--solver", type=click.Choice(["ls", "tls", "bayes", "bounded"]), default="bounded", show_default=True)
@click.option("--params", default=None, help="comma-separated parameter names (default: all [[parameters]])")
@click.option("--max-iter", type=click.IntRange(min=1), default=20, show_default=True)
@click.option("--tol", "tol_pct", type=float, default=0.1, show_default=True,  # problems.run.TOL_FREQ_PCT
              help="stop when the max frequency error is below this percentage (eq. 7.2)")
@click.option("--mesh-size", default=None, help="override board.mesh_size, e.g. '10 mm'")
@click.option("--noise", default=None,
              help="the test's noise in percent, e.g. f=0.2,shape=2 (uniform bounds): the weights and the chi^2 "
                   "verdict of the fit (default f=0.2,shape=2, assumed)")
@click.option("--mesh-check/--no-mesh-check", default=True, show_default=True,
              help="modal methods: the model on a mesh twice as fine at the fitted parameters, whose mesh error "
                   "joins the noise and is taken out of the measured frequencies")
@folder_outputs("folder for board.updated.toml, the iteration plot and tables (default: board.updated.toml beside "
                "the board)", "write parameters, status, before/after and history as JSON", html=True,
                force="replace an earlier board.updated.toml beside the board (default: a numbered name), and write "
                      "it even when the fit did not converge")
@library_option()
@units_option
def command(board_toml, test_uff, configs, freq_csv, method, frf_freqs, damping, solver, params, max_iter, tol_pct,
            mesh_size, noise, mesh_check, out, force, json_path, html):
    """Update a structure's [[parameters]] against modal tests: TEST_UFF for the base configuration and
    NAME=FILE for each perturbed configuration of board.toml (e.g. c2=test2.uff), or measured
    frequencies (--frequencies CSV)."""
    from ..problems import UpdateProblem, load_structure, run
    from ..problems.fit import fit
    from ..problems.frf_tests import frf_configurations
    from ..problems.run import outcome
    from ..report import update_report as rep
    from ..report.files import write_json, write_text
    from ..testdata.measured import read_frequency_table
    from ..units import to_si

    if (test_uff is None) == (freq_csv is None):
        fail("give either TEST_UFF (and NAME=FILE for other configurations) or --frequencies FILE.csv")
    if freq_csv is not None and method != "freq":
        fail("--frequencies holds no shapes: use --method freq")
    noise = parse_noise(noise)
    with input_errors():
        board = load_structure(board_toml)
        ms = to_si(mesh_size, "mm", "--mesh-size") if mesh_size else None
        t0 = step("building the models")
        problem = UpdateProblem(board, params.split(",") if params else None, mesh_size=ms)
        if method.startswith("frf"):
            freqs = None if frf_freqs is None else parse_frf_freqs(frf_freqs)
            check, cfgs, notes = frf_configurations(problem, [(None, test_uff)] + parse_extra(configs), method,
                                                    freqs, damping)
            for note in notes:
                click.echo(f"note: {note}", err=True)
        elif freq_csv is not None:
            data = read_frequency_table(freq_csv, board)
            click.echo("frequencies only: test mode n is paired with elastic model mode n (by order)", err=True)
        else:
            data = measured_configurations(board, test_uff, configs)
        done(t0)
        n_tests = len(check) if method.startswith("frf") else len(data)
        t0 = step(f"updating {len(problem.names)} parameter(s) with {method}/{solver} on {n_tests} test "
                  "configuration(s)")
        if method.startswith("frf"):
            blocks = f" ({len(cfgs)} equation blocks)" if len(cfgs) != len(check) else ""
            click.echo(f"    {len(cfgs)} FRF configuration(s){blocks}", err=True)
            res, before, after = run(problem, cfgs, solver, check=check, max_iter=max_iter, tol_freq_pct=tol_pct,
                                     progress=lambda h: click.echo(rep.progress_line(h), err=True))
            what, fitted = outcome(problem, res, before, after), None
        else:
            fitted = fit(problem, data, method=method, noise=noise, mesh_check=mesh_check, solver=solver,
                         max_iter=max_iter, tol_freq_pct=tol_pct,
                         progress=lambda msg: click.echo(f"    {msg}", err=True))
            res, before, after = fitted.result, fitted.before, fitted.after
            what = {"status": fitted.status, "details": fitted.details, "warnings": fitted.warnings}
        done(t0)
        rows = rep.parameter_rows(problem, res.p)
        source = f"pcbdyn update ({what['status']})"
        written = what["status"] == "converged" or force
        if out is None:
            dst = problem.write_updated(res.p, result_path(None, board_toml, "updated", force),
                                        source=source) if written else None
        else:
            from ..report.manifest import replacing

            with replacing(out, "pcbdyn update") as staged:  # the earlier --out stays whole until all is written
                dst = staged.final(problem.write_updated(res.p, result_path(staged.path, board_toml, "updated"),
                                                         source=source)) if written else None
                rep.plot_iterations(staged.path / "iterations.png", problem, res)
                write_text(staged.path / "parameters.txt", rep.format_parameters(rows) + "\n")
                write_text(staged.path / "correlation.txt", rep.format_correlation(before, after) + "\n")
                if html:
                    from ..fe.modal import solve_modes

                    built = problem.system(None).at(res.p)
                    modes = solve_modes(built.model, n_modes=board.analysis.modes, f_max=board.analysis.f_max)
                    page = staged.final(rep.html_page(staged.path, board_toml, board, rows, before, after, what,
                                                      (built, modes), staged.path / "iterations.png"))
                    click.echo(f"page written to {page}", err=True)
    click.echo(f"\n{board.name}: {what['status']} after {res.iterations} iteration(s) ({res.reason})")
    echo_verdict(what)
    click.echo(rep.format_parameters(rows))
    click.echo("")
    click.echo(rep.format_correlation(before, after))
    if dst is None:
        click.echo(f"\nno updated board written: the fit did not converge ({what['status']}); --force writes it anyway",
                   err=True)
    else:
        click.echo(f"\nupdated board written to {dst}", err=True)
    if json_path is not None:
        write_json(json_path, rep.update_json(problem, res, rows, before, after, what, method, solver, dst, fitted))
