"""``pcbdyn identify frfs.uff --band 50,2000Hz --out modes.uff``: modal parameters from measured FRFs
(LSCF poles over model orders, stabilisation chart, automatic or manual pole choice, LSFD
residues; :mod:`pcbdyn.identification`), written as UFF 55 with damping, ready for
``pcbdyn correlate``."""

from __future__ import annotations

import math
from pathlib import Path

import click
import numpy as np

from .common import checked_outputs, done, fail, number_pair, step, units_option


def parse_select(text: str) -> list:
    """'197.9,277 Hz,394.6' -> frequencies [Hz]; a usage error otherwise."""
    from ..units import UnitError, to_si

    out = []
    for part in (p.strip() for p in str(text).split(",")):
        try:
            out.append(float(part) if part.replace(".", "", 1).isdigit() else to_si(part, "Hz", "--select"))
        except (UnitError, ValueError):
            raise click.BadParameter(f"'{part}' is not a frequency, e.g. 197.9 or '197.9 Hz'",
                                     param_hint="--select") from None
    if not out or any(not f > 0 for f in out):
        raise click.BadParameter(f"'{text}' is not a list of positive frequencies", param_hint="--select")
    return out


def _number_or_none(v) -> float | None:
    """A JSON value: the float, or None (null) where there is none (NaN: a mode without that neighbour)."""
    return None if math.isnan(v) else float(v)


@click.command("identify")
@click.argument("frfs_uff", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--band", default=None, help="frequency band lo,hi in Hz, e.g. 50,2000Hz (default: the FRFs' axis)")
@click.option("--poles", "max_order", type=click.IntRange(min=2), default=40, show_default=True,
              help="highest number of pole pairs fitted (model orders 2, 4, ..., 2N)")
@click.option("--select", default=None, help="pick the modes near these frequencies [Hz] instead of the automatic choice")
@click.option("--kind", type=click.Choice(["receptance", "mobility", "accelerance"]), default=None,
              help="FRF kind, for files whose datasets do not say")
@click.option("--points", "points_file", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="the measurement points, for an FRF file without geometry: a points CSV (point, x [mm], y [mm], "
                   "z [mm]) or a UFF file with datasets 15/2411")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=Path("modes.uff"), show_default=True,
              help="UFF file to write (points 2411, modes 55 with damping)")
@click.option("--chart", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="stabilisation chart PNG (default: next to --out, <stem>.stabilisation.png)")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write the modes (frequency_hz, damping_ratio, quality indicators, spread over the stable poles, "
                   "MAC to neighbours) and the choice's criteria as JSON")
@checked_outputs(folders=(), files=("json_path", "out", "chart"))
@units_option
def command(frfs_uff, band, max_order, select, kind, points_file, out, chart, json_path):
    """Identify modes (frequency, damping, shape) from measured FRFs at one or several references."""
    from ..identification import identify
    from ..report.files import write_json
    from ..report.stabilisation import stabilisation_chart
    from ..testdata import TestData, TestDataError, read_uff, write_uff
    from ..testdata.measured import read_geometry

    band = number_pair(band, "--band", "Hz") if band is not None else None
    picks = parse_select(select) if select is not None else None
    chart = chart or out.with_name(f"{out.stem}.stabilisation.png")
    try:
        data = read_uff(frfs_uff, points=None if points_file is None else read_geometry(points_file), frf_kind=kind)
        if data.frfs is None:
            raise TestDataError(f"{frfs_uff}: no FRFs (UFF dataset 58, function type 4) in the file; identify "
                                "needs the measured FRFs, each with its response and reference DOF")
        frfs = data.frfs
        try:
            frfs.points.index(np.union1d(frfs.response.point_ids, frfs.reference.point_ids))
        except TestDataError as exc:
            raise TestDataError(f"{frfs_uff if points_file is None else points_file}: {exc}; identify takes them "
                                "with --points FILE (a points CSV or a UFF file with the geometry)") from None
        t0 = step(f"LSCF on {len(frfs.response)} responses x {len(frfs.reference)} reference(s), "
                  f"orders up to {2 * max_order}")
        result = identify(frfs, band, max_order, picks)
        done(t0)
        write_uff(out, TestData(frfs.points, result.modes))
        stabilisation_chart(chart, result, frfs)
    except TestDataError as exc:
        fail(str(exc))
    m = result.modes
    lo, hi = result.band
    click.echo(f"\n{frfs_uff.name}: {m.n_modes} mode(s) in {lo:g}-{hi:g} Hz ({result.selection} choice, shapes "
               f"{'mass-normalised at the driving point' if result.scaling == 'mass' else 'scaled to 1'})")
    if m.n_modes:
        click.echo(f"{'mode':>4}  {'f [Hz]':>10}  {'+- [Hz]':>8}  {'damping [%]':>11}  {'+- [%]':>7}  {'MPC':>6}  "
                   f"{'MPD [deg]':>9}  {'MAC prev':>8}  {'MAC next':>8}")
    for j, q in enumerate(result.quality):
        prev, nxt = (f"{v:8.3f}" if not math.isnan(v) else f"{'-':>8}" for v in result.mac_neighbours[j])
        click.echo(f"{j + 1:4d}  {m.frequencies[j]:10.2f}  {q['frequency_std_hz']:8.3f}  {100 * m.damping[j]:11.3f}  "
                   f"{100 * q['damping_std']:7.3f}  {q['mpc']:6.3f}  {q['mpd_deg']:9.2f}  {prev}  {nxt}")
    if not m.n_modes:
        click.echo("no pole is stable over the model orders in this band: no mode identified")
    for note in result.notes:
        click.echo(f"note: {note}", err=True)
    click.echo(f"written {out} and {chart}", err=True)
    if json_path is not None:
        write_json(json_path, {
            "source": str(frfs_uff), "uff": str(out), "chart": str(chart), "band_hz": [lo, hi],
            "max_order": 2 * result.max_order, "selection": result.selection, "scaling": result.scaling,
            "frf_kind": frfs.kind, "response_dofs": len(frfs.response),
            "references": [{"point": int(p), "direction": [float(v) for v in d]}
                           for p, d in zip(frfs.reference.point_ids, frfs.reference.directions)],
            "criteria": result.criteria, "notes": result.notes,
            "modes": [{"n": j + 1, "frequency_hz": float(m.frequencies[j]), "damping_ratio": float(m.damping[j]),
                       **result.quality[j], "mac_neighbours": {"previous": _number_or_none(result.mac_neighbours[j, 0]),
                                                               "next": _number_or_none(result.mac_neighbours[j, 1])}}
                      for j in range(m.n_modes)],
        })
