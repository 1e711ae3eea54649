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
import numpy as np

from .common import done, fail, measured_configurations, parse_extra, parse_noise, step

METHOD_CHOICES = ["tls-qrf", "svd-qr", "qr", "min-norm"]


def evidence(method, A, b, names, rank=None, alpha=0.8, redraws=()) -> tuple:
    """(dict for JSON, the TLS/QR-F Subset). The 5.2.3 check, condition curve and rank always come
    from TLS/QR-F; selection and solution from ``method``. ``redraws``: equations rebuilt with the
    stated noise drawn again (:func:`noise_redraws`); with them b is weighted for TLS by the errors
    the noise makes (else eq. 4.43 with k_A = k_b) and b counts as explained up to the part of
    those errors outside range(A)."""
    from ..updating.study import localise
    from ..updating.subset import EXPLAIN_TOL, explain_tol_from_noise, tls_qrf
    from ..updating.weighting import tls_column_weight_from_noise

    r = None if rank is None else (rank if rank >= 0 else A.shape[1] + rank)
    t_b = tls_column_weight_from_noise(A, b, redraws) if redraws else None
    tol = explain_tol_from_noise(A, b, redraws) if redraws else EXPLAIN_TOL
    tls = tls_qrf(A, b, rank=r, alpha=alpha, t_b=t_b, explain_tol=tol)
    if method == "tls-qrf":
        sel, order, ratios = tls.selected, tls.order, tls.descending_ratio
    else:
        sel, order, ratios = localise(method, A, b, rank, t_b), np.zeros(0, int), np.zeros(0)
    x = np.zeros(A.shape[1])
    if sel.size:
        x[sel] = np.linalg.lstsq(A[:, sel], b, rcond=None)[0]
    data = {
        "method": method,
        "tls_weight": t_b,
        "explain_tol_pct": 100.0 * tol,
        "selected": [names[i] for i in sel],
        "order": [names[i] for i in order],
        "descending_ratio": [float(v) for v in ratios],
        "solution": {names[i]: float(x[i]) for i in sel},
        "rank": int(tls.rank),
        "condition_curve": [float(v) if np.isfinite(v) else None for v in tls.condition_curve],
        "explains_data": bool(tls.explains_data),
        "out_of_range_pct": 100.0 * float(tls.out_of_range),
        "message": tls.message,
    }
    return data, tls


def noise_redraws(problem, tests, eq_type, matching, shape, freq_pct, shape_pct, seed: int = 0) -> list:
    """Equations (A_d, b_d) rebuilt from the measured data with the stated noise drawn again
    (eqs. 5.72-5.73), those that pair like the data (``shape`` of A): what the noise does to the
    equations, for the TLS weight of b and the 5.2.3 check."""
    from dataclasses import replace

    from ..updating.board_problem import config_pairing
    from ..updating.iteration import build_equations
    from ..updating.success import add_noise
    from ..updating.weighting import NOISE_REDRAWS

    rng = np.random.default_rng(seed)
    redraws = []
    for _ in range(NOISE_REDRAWS):
        cfgs = [problem.configuration(name, replace(
            m, frequencies=add_noise(m.frequencies, freq_pct or 0.0, rng),
            shapes=None if m.shapes is None else add_noise(m.shapes, shape_pct or 0.0, rng)), eq_type,
            matching=matching) for name, m in tests]
        (Ad, bd), _, _ = build_equations(cfgs, problem.p0, config_pairing(cfgs))
        if Ad.shape == shape:
            redraws.append((Ad, bd))
    return redraws


def fbm_map(path, cfg, state, xy):
    """FBM residual forces (eq. 5.2) of the base configuration's measured modes: the shapes are
    expanded to the model (eq. 2.25), the residuals read back at the measured points (the
    expansion leaves none elsewhere), scaled per mode to a maximum of 1, summed over the modes
    and drawn over the measured points (as thesis Fig. 5.1, on the board)."""
    from ..report.localisation_plots import save_map
    from ..updating import matching
    from ..updating.indicators import fbm_residuals

    K, M, used = state["K"], state["M"], state["used"]
    om = 2 * np.pi * np.asarray(cfg.f_x, float)[used]
    phi = matching.expand(K, M, cfg.P, np.asarray(cfg.phi_x)[:, used], om)
    res = np.abs(np.asarray(cfg.P @ fbm_residuals(K, M, om, phi)))
    peak = res.max(axis=0)
    values = (res / np.where(peak > 0, peak, 1.0)).sum(axis=1)
    save_map(path, xy, None, values, "FBM residual forces at the test points (eq. 5.2)")
    return values


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
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="folder for the evidence figure and the FBM map (PNG)")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None)
def command(board_toml, test_uff, config_tests, method, eq_type, params, rank, alpha, noise, matching, out,
            json_path):
    """Localise model errors among the board's parameters from one or more modal tests
    (extra tests as CONFIG=test.uff for configurations of board.toml)."""
    from ..board import load_board
    from ..report.files import write_json
    from ..testdata import TestDataError
    from ..board import BoardError
    from ..updating.board_problem import BoardProblem, config_pairing
    from ..updating.iteration import build_equations

    extra = parse_extra(config_tests)
    freq_pct, shape_pct = parse_noise(noise)
    try:
        board = load_board(board_toml)
        names = [n.strip() for n in params.split(",")] if params else None
        t0 = step("building the model and its parameter derivatives")
        problem = BoardProblem(board, names)
        configs = []
        tests = measured_configurations(board, test_uff, config_tests)
        for (name, measured), (_, path) in zip(tests, [(None, test_uff)] + extra):
            if eq_type in ("qms", "fbm") and measured.shapes is None:
                raise ValueError(f"{path.name}: --equations {eq_type} needs mode shapes")
            configs.append(problem.configuration(name, measured, eq_type, matching=matching))
            if name is None:
                measured_xy = None if measured.xyz is None else measured.xyz[:, :2]
        (A, b), _, states = build_equations(configs, problem.p0, config_pairing(configs))
        redraws = [] if noise is None else noise_redraws(problem, tests, eq_type, matching, A.shape, freq_pct,
                                                          shape_pct)
        done(t0)
    except (ValueError, KeyError, TestDataError, BoardError) as exc:
        fail(str(exc).strip("'\""))
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
        from ..report.localisation_plots import localisation_figure

        out.mkdir(parents=True, exist_ok=True)
        localisation_figure(out / "localisation.png", tls, problem.names)
        if eq_type in ("qms", "fbm") and measured_xy is not None:
            fbm = fbm_map(out / "fbm_map.png", configs[0], states[0], measured_xy)
            data["fbm_peak_mm"] = [1e3 * float(v) for v in measured_xy[int(np.argmax(fbm))]]
        drawn = ", fbm_map.png" if "fbm_peak_mm" in data else ""
        click.echo(f"wrote {out}/localisation.png{drawn}", err=True)
    if json_path is not None:
        write_json(json_path, data)
