"""``pcbdyn simulate-test board.toml --points points.csv --excite x,y``: a modal test as it would be
measured on the model (modes and FRFs at the points, with the thesis' noise, eq. 5.72-5.74), as UFF.

To simulate a "true" structure that differs from the model, describe it in a second board.toml.
"""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from ..domain import MAX_MODES
from .common import PROBE_TOL, checked_outputs, done, input_errors, library_option, number_pair, solve_structure, step


def check_band(f_range, df: float) -> None:
    """Usage errors for --df and --f-range, before any solving."""
    if not df > 0:
        raise click.BadParameter(f"{df} is not a positive step in Hz", param_hint="--df")
    if f_range is not None and not (0 <= f_range[0] < f_range[1]):
        raise click.BadParameter(f"{f_range[0]:g},{f_range[1]:g} is not a range 0 <= f_lo < f_hi in Hz",
                                 param_hint="--f-range")


@click.command("simulate-test")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--points", "points_csv", required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path),
              help="measurement points CSV: point,x [mm],y [mm][,dir] (dir default +z)")
@click.option("--config", default=None, help="configuration name from [[configurations]]")
@click.option("--excite", required=True, help="excitation point x,y on the board (x,y,z on a box), in mm unless units "
                                              "are given")
@click.option("--excite-dir", type=click.Choice(["+x", "-x", "+y", "-y", "+z", "-z"]), default="+z", show_default=True,
              help="direction of the excitation force")
@click.option("--noise", default="0", show_default=True,
              help="noise in percent: one number for all, or 'f=0.2,shape=2,frf=1' (thesis eq. 5.72-5.74)")
@click.option("--seed", type=int, default=None, help="random seed, for repeatable noise")
@click.option("--f-range", "f_range", default=None, help="FRF lines f_lo,f_hi in Hz (default df to 1.2 x top mode)")
@click.option("--df", type=float, default=1.0, show_default=True, help="FRF line spacing [Hz]")
@click.option("--damping", type=float, default=0.01, show_default=True, help="viscous damping ratio of every mode")
@click.option("--kind", type=click.Choice(["receptance", "mobility", "accelerance"]), default="accelerance",
              show_default=True, help="FRF kind")
@click.option("--modes", "n_modes", type=click.IntRange(1, MAX_MODES), default=None,
              help="number of modes written (default: [analysis] modes of the board); the FRFs sum every mode up to "
                   "twice the band's top")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=Path("test.uff"), show_default=True,
              help="UFF file to write (points 2411, modes 55, FRFs 58)")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write a summary (frequencies, points, excitation, noise) as JSON")
@checked_outputs(folders=(), files=("json_path", "out"))
@library_option()
def command(board_toml, points_csv, config, excite, excite_dir, noise, seed, f_range, df, damping, kind, n_modes, out,
            json_path):
    """Simulate a modal test on a board model: modes and FRFs at measurement points, with noise."""
    from ..problems import load_structure
    from ..report.files import write_json
    from ..testdata import Noise, Points, TestDataError, read_points_csv, write_uff
    from ..testdata.data import check_damping
    from ..testdata.simulate import frequency_axis, frf_modes, simulate_on_model

    xyz = (number_pair(excite, "--excite", "mm", counts=(2, 3)) + (0.0,))[:3]
    direction = (-1.0 if excite_dir[0] == "-" else 1.0) * np.eye(3)["xyz".index(excite_dir[1])]
    band = number_pair(f_range, "--f-range") if f_range is not None else None
    check_band(band, df)
    try:
        noise_levels = Noise.parse(noise)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="--noise") from None
    try:
        check_damping([damping], 1, "")
    except TestDataError as exc:
        raise click.BadParameter(str(exc), param_hint="--damping") from None
    with input_errors():
        board = load_structure(board_toml)
        points, dofs = read_points_csv(points_csv)
        board.check_points(points, points_csv)
        board.check_points(Points([0], [xyz]), "--excite")
        bm, modes, K, M = solve_structure(board, config, n_modes=n_modes)
        f_axis = frequency_axis(band, df, float(modes.frequencies.max()))
        if f_axis[0] == 0 and modes.n_rigid and kind != "accelerance":
            raise click.BadParameter(f"a free structure's {kind} is infinite at 0 Hz: start the band above 0 "
                                     f"(e.g. {df:g},{f_axis[-1]:g})", param_hint="--f-range")
        t0 = step(f"solving the modes up to twice the band's top ({2 * f_axis[-1]:g} Hz) for the FRFs")
        summed = frf_modes(bm.model, modes, f_axis, K, M)
        done(t0)
        t0 = step(f"reading the model at {len(dofs)} DOFs and summing {summed.frequencies.size} modes and the "
                  f"static compliance of the others over {f_axis.size} lines")
        data = simulate_on_model(bm.model, modes, points, dofs, excite=xyz, excite_direction=direction, f_axis=f_axis,
                                 zeta=damping, kind=kind, noise=noise_levels, seed=seed, tol=PROBE_TOL,
                                 frf_modes=summed, K=K, M=M)
        done(t0)
        write_uff(out, data)
    ref_id = int(data.frfs.reference.point_ids[0])
    click.echo(f"\n{board.name} [{config or 'base'}]: simulated test, {len(dofs)} response DOFs, "
               f"excitation at point {ref_id} ({', '.join(f'{v * 1e3:g}' for v in xyz)} mm, {excite_dir})")
    click.echo(f"noise: frequencies {noise_levels.frequency_pct:g} %, shapes {noise_levels.shape_pct:g} %, "
               f"FRFs {noise_levels.frf_pct:g} %; damping ratio {damping:g}; {kind} FRFs "
               f"{f_axis[0]:g}-{f_axis[-1]:g} Hz every {df:g} Hz")
    click.echo("mode  frequency [Hz]")
    for j, f in enumerate(data.modes.frequencies, start=1):
        click.echo(f"{j:4d}  {f:14.2f}")
    click.echo(f"written {out}", err=True)
    if json_path is not None:
        write_json(json_path, {
            "board": board.name, "configuration": config or "base", "uff": str(out),
            "modes": [{"n": j + 1, "frequency_hz": float(f), "damping_ratio": float(z)}
                      for j, (f, z) in enumerate(zip(data.modes.frequencies, data.modes.damping))],
            "model_frequencies_hz": [float(f) for f in modes.frequencies],
            "frf_modes_summed": int(summed.frequencies.size),
            "points": len(points), "response_dofs": len(dofs),
            "excitation": {"point": ref_id, "x_m": xyz[0], "y_m": xyz[1], "z_m": xyz[2], "direction": excite_dir},
            "noise_pct": {"frequency": noise_levels.frequency_pct, "shape": noise_levels.shape_pct,
                          "frf": noise_levels.frf_pct},
            "seed": seed, "frf": {"kind": kind, "f_min_hz": float(f_axis[0]), "f_max_hz": float(f_axis[-1]),
                                  "df_hz": df, "lines": int(f_axis.size)},
        })

