"""Pieces shared by the commands: progress lines, solving one board configuration, option parsing."""

from __future__ import annotations

import sys
import time

import click


#: [m] how far off the board's mid-plane a measurement point may be (points on the top surface, or
#: on top of a part, are given with such z offsets); the points' x, y are checked against the outline
PROBE_TOL = 0.02


def step(msg: str) -> float:
    """Print a progress line on stderr; returns the start time for :func:`done`."""
    click.echo(f"  {msg} ...", err=True)
    return time.perf_counter()


def done(t0: float) -> None:
    click.echo(f"    done in {time.perf_counter() - t0:.1f} s", err=True)


def fail(message: str, code: int = 2):
    """Print ``error: message`` on stderr and leave with ``code`` (nothing else is written)."""
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


def solve_board(board, config: str | None, n_modes: int | None = None, f_max: float | None = None):
    """Build the FE model of one configuration of ``board`` and solve its modes, with progress.

    Returns (board_model, modes, K, M). ``n_modes``/``f_max`` default to the board's [analysis].
    """
    from ..board import build_model
    from ..fe.assembly import assemble
    from ..fe.modal import solve_modes

    label = config or "base"
    n_modes = board.analysis.modes if n_modes is None else n_modes
    f_max = board.analysis.f_max if f_max is None else f_max
    t0 = step(f"[{label}] meshing and building the model")
    bm = build_model(board, config)
    done(t0)
    t0 = step(f"[{label}] solving {bm.model.n_dof} DOFs for {n_modes} modes")
    K, M = assemble(bm.model)
    modes = solve_modes(bm.model, n_modes=n_modes, f_max=f_max, K=K, M=M)
    done(t0)
    return bm, modes, K, M


def number_pair(text: str, option: str, unit: str | None = None) -> tuple:
    """Two comma-separated values such as "135,63.57" (in ``unit`` when the values carry none,
    e.g. mm) or "135 mm, 63.57 mm", as SI floats; a clear usage error otherwise."""
    from ..units import UnitError, to_si

    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) != 2 or not all(parts):
        raise click.BadParameter(f"'{text}' is not two comma-separated values, e.g. '135,63.57'",
                                 param_hint=option)
    out = []
    for p in parts:
        try:
            v = float(p)
            out.append(to_si(f"{v} {unit}", unit) if unit else v)
        except ValueError:
            if unit is None:
                raise click.BadParameter(f"'{p}' is not a number", param_hint=option) from None
            try:
                out.append(to_si(p, unit, option))
            except UnitError as exc:
                raise click.BadParameter(str(exc), param_hint=option) from None
    return tuple(out)


def points_on_board(board, points, source, board_toml) -> None:
    """Raise TestDataError naming the points (by id) of ``source`` that lie off the outline or in a
    hole of the board, before any meshing."""
    from ..testdata import TestDataError

    off = ~board.outline.contains(points.xyz[:, :2], tol=1e-6)
    if off.any():
        listed = ", ".join(f"{int(i)} ({x * 1e3:g}, {y * 1e3:g} mm)"
                           for i, (x, y) in zip(points.ids[off][:10], points.xyz[off, :2][:10]))
        lo, hi = board.outline.bbox
        raise TestDataError(
            f"{source}: {int(off.sum())} point(s) lie off the board of {board_toml.name}: {listed}"
            f"{' ...' if off.sum() > 10 else ''}. The board frame runs from ({lo[0] * 1e3:g}, {lo[1] * 1e3:g}) to "
            f"({hi[0] * 1e3:g}, {hi[1] * 1e3:g}) mm; give the points in that frame and state their unit in the "
            "header (e.g. 'x [mm]')")


def parse_extra(items) -> list:
    """NAME=FILE arguments -> [(configuration name, Path)]."""
    from pathlib import Path

    out = []
    for it in items:
        name, sep, path = it.partition("=")
        if not sep or not name or not path:
            raise click.BadParameter(f"'{it}' is not NAME=FILE (a configuration of board.toml and its test, "
                                     "e.g. c2=test2.uff)", param_hint="CONFIGS")
        if not Path(path).is_file():
            raise click.BadParameter(f"'{path}' does not exist", param_hint="CONFIGS")
        out.append((name, Path(path)))
    return out


def measured_configurations(board, test_uff, extras) -> list:
    """[(configuration name or None, MeasuredModes)] of the base test and every NAME=FILE; a
    BoardError for a configuration board.toml does not declare."""
    from ..board import BoardError
    from ..updating.board_problem import MeasuredModes
    from .correlate import load_test_modes

    extra = parse_extra(extras)  # usage errors before any file is read
    data = [(None, MeasuredModes.from_test(load_test_modes(test_uff)))]
    for name, path in extra:
        if board.configuration(name) is None:
            raise BoardError(f"{board.path.name}: configuration '{name}' (from {name}={path}) is not in "
                             "[[configurations]]")
        data.append((name, MeasuredModes.from_test(load_test_modes(path))))
    return data


def parse_noise(text):
    """'f=0.2,shape=2' -> (frequency %, shape %), None where not given (or 0)."""
    from ..testdata.noise import Noise

    if text is None:
        return None, None
    try:
        n = Noise.parse(text)
    except ValueError as exc:
        raise click.BadParameter(f"{exc}; e.g. --noise f=0.2,shape=2 (percent, uniform bounds)",
                                 param_hint="--noise") from None
    return n.frequency_pct or None, n.shape_pct or None
