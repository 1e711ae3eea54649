"""``pcbdyn localize board.toml test.uff [c2=test2.uff ...] --method tls-qrf [--json PATH]``:
which of the board's ``[[parameters]]`` carry the model errors (thesis ch. 5).

The measured modes of each test configuration are paired with the model's, the weighted
updating equations of all configurations are stacked (PBC, eq. 6.4) and a subset of the
parameters is selected (TLS/QR-F by default, section 5.2.3), with the evidence: selection order,
residue descending ratios (eq. 5.60), subset solution, the epsilon-condition curve and rank, and
the section 5.2.3 check whether the parameters can explain the data at all (with ``--noise``, b is
weighted for TLS and judged against what that noise makes of the equations). With ``--out``, the
evidence figure (as thesis Fig. 5.13) and an FBM map of the base configuration (eq. 5.2) are drawn.
"""

from __future__ import annotations

from pathlib import Path

import click

from .common import done, folder_outputs, input_errors, library_option, measured_configurations, parse_extra, parse_noise, step, units_option

METHOD_CHOICES = ["tls-qrf", "svd-qr", "qr", "min-norm"]


@click.command("localize")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("test_uff", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("config_tests", nargs=-1)
@click.option("--method", type=click.Choice(METHOD_CHOICES), default="tls-qrf", show_default=True,
              help="subset selection: TLS/QR-F (5.2.3), SVD/QR (5.2.2), QR basic solution, minimum-norm LS")
@click.option("--equations", "eq_type", type=click.Choice(["qms", "fbm", "freq", "freq-rel"]), default="qms",
              show_default=True, help="updating equations from the measured modes")
@click.option("--params", default=None, help="comma-separated parameter names (default: all [[parameters]])")
@click.option("--rank", type=int, default=None, help="numerical rank (k, or -k = n_params - k); default automatic")
@click.option("--alpha", type=float, default=0.8, show_default=True, help="backward exclusion factor (eq. 5.62)")
@click.option("--noise", default=None,
              help="measurement noise in percent as uniform bounds (thesis eqs. 5.72-5.73), e.g. 'f=0.2,shape=2': "
                   "b is weighted for TLS by the errors it makes in the equations (default: eq. 4.43, k_A = k_b)")
@click.option("--matching", type=click.Choice(["reduce", "expand"]), default="reduce", show_default=True,
              help="Guyan-reduce the model to the measured DOFs, or expand the measured shapes")
@folder_outputs("folder for the evidence figure and the FBM map (PNG)",
                "write the selection and its evidence as JSON")
@library_option()
@units_option
def command(board_toml, test_uff, config_tests, method, eq_type, params, rank, alpha, noise, matching, out,
            json_path):
    """Localise model errors among a structure's [[parameters]] from modal tests: TEST_UFF of the base
    configuration and NAME=FILE for each perturbed configuration of board.toml (e.g. c2=test2.uff)."""
    from ..problems import UpdateProblem, load_structure
    from ..problems.localize import evidence, noise_redraws
    from ..report.files import write_json
    from ..updating.iteration import build_equations

    extra = parse_extra(config_tests)
    freq_pct, shape_pct = parse_noise(noise)
    with input_errors():
        board = load_structure(board_toml)
        names = [n.strip() for n in params.split(",")] if params else None
        t0 = step("building the model and its parameter derivatives")
        problem = UpdateProblem(board, names)
        configs = []
        tests = measured_configurations(board, test_uff, config_tests)
        for (name, measured), (_, path) in zip(tests, [(None, test_uff)] + extra):
            if eq_type in ("qms", "fbm") and measured.shapes is None:
                raise ValueError(f"{path.name}: --equations {eq_type} needs mode shapes")
            configs.append(problem.configuration(name, measured, eq_type, matching=matching))
        (A, b), _, states = build_equations(configs, problem.p0)
        redraws = [] if noise is None else noise_redraws(problem, tests, eq_type, matching, A.shape, freq_pct,
                                                          shape_pct)
        done(t0)
    data, tls = evidence(method, A, b, problem.names, rank, alpha, redraws)
    data["configurations"] = ["base"] + [n for n, _ in extra]
    data["equations"] = eq_type
    click.echo(f"\n{board.name}: {len(problem.names)} parameters, {A.shape[0]} equations ({eq_type}), "
               f"rank {data['rank']}; method {method}")
    if data["order"]:
        click.echo("selection order: " + ", ".join(f"{n} ({r:.1f} %)" for n, r in
                                                    zip(data["order"], data["descending_ratio"])))
    click.echo("selected: " + (", ".join(f"{n} {100 * v:+.1f} %" for n, v in data["solution"].items()) or "none"))
    if not data["explains_data"]:
        click.echo("warning: " + data["message"])
    if out is not None:
        from ..problems.localize import fbm_map
        from ..report.localisation_plots import localisation_figure, save_map
        from ..report.manifest import replacing

        written = ["localisation.png"]
        with replacing(out, "pcbdyn localize") as run:  # the earlier --out stays whole until all is written
            localisation_figure(run.path / written[0], tls, problem.names)
            measured = tests[0][1]
            if eq_type in ("qms", "fbm") and measured.shapes is not None:
                xy = measured.xyz[:, :2] if getattr(board, "outline", None) is not None else measured.xyz  # a box: 3-D
                fbm, peak = fbm_map(configs[0], states[0])
                written.append("fbm_map.png")
                save_map(run.path / written[-1], xy, None, fbm, "FBM residual forces at the test points (eq. 5.2)")
                data["fbm_peak_mm"] = [1e3 * float(v) for v in xy[peak]]
        click.echo(f"wrote {', '.join(str(out / w) for w in written)}", err=True)
    if json_path is not None:
        write_json(json_path, data)
