"""``pcbdyn library list`` and ``pcbdyn library show FAMILY``: the part families the library search path
finds (``--library DIR`` first), their calibrated equivalent thickness with its standard deviation, and
the calibration runs behind a value (table, and with ``--plot`` the value and its band against the runs).
"""

from __future__ import annotations

from pathlib import Path

import click

from .common import checked_outputs, fail, library_option


@click.group("library")
def command():
    """The component library: part families and their calibrations."""


@command.command("list")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write the families as JSON ('-': standard output)")
@checked_outputs(folders=())
@library_option()
def list_command(json_path):
    """The part families the library search path finds (first match of each name)."""
    from ..components.library import LibraryError, available, locate, search_path
    from ..components.writer import read_entry
    from ..report import calibration_report as rep
    from ..report.files import write_json

    try:
        rows = rep.library_rows([(p, *read_entry(p)[1:]) for p in (locate(n) for n in available())])
    except LibraryError as exc:
        fail(str(exc))
    click.echo(rep.format_library(rows))
    click.echo("searched: " + ", ".join(str(d) for d in search_path()), err=True)
    if json_path is not None:
        write_json(json_path, {"families": rows, "search_path": [str(d) for d in search_path()]})


@command.command("show")
@click.argument("family")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="PNG of the runs' values +- sd and the pooled value with its band")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write the entry and its runs as JSON ('-': standard output)")
@checked_outputs(folders=(), files=("json_path", "plot_path"))
@library_option()
def show_command(family, plot_path, json_path):
    """A family's library entry and the calibration runs behind its value."""
    import math

    from ..components.library import LibraryError, available, locate
    from ..components.records import pool
    from ..components.writer import read_entry
    from ..report import calibration_report as rep
    from ..report.files import write_json

    path = locate(family)
    if path is None:
        fail(f"family '{family}' is not in the library (known: {', '.join(available())})")
    try:
        _, pkg, records = read_entry(path)
    except LibraryError as exc:
        fail(str(exc))
    pooled = pool(records)
    sd = pkg.equivalent_thickness_std
    click.echo(f"{pkg.name} ({path}): equivalent thickness {pkg.equivalent_thickness * 1e3:.4g} mm"
               + (f" +- {sd * 1e3:.2g} mm" if sd is not None else " (no standard deviation: not calibrated)")
               + f"; {len(records)} calibration run(s), {sum(r.flagged for r in records)} flagged"
               + ("" if pooled is None or pooled.n < 2 else f"; Birge ratio {pooled.birge:.2f}"))
    if records:
        click.echo(rep.format_runs(records))
    if plot_path is not None:
        rep.plot_runs(plot_path, pkg.name, records, pooled, records[0].before if records else None)
        click.echo(f"plot written to {plot_path}", err=True)
    if json_path is not None:
        def num(v):
            return v if math.isfinite(v) else None

        write_json(json_path, {
            "family": pkg.name, "file": str(path), "equivalent_thickness_m": pkg.equivalent_thickness, "std_m": sd,
            "pooled": None if pooled is None else {"value_m": pooled.value, "std_m": pooled.std, "n": pooled.n,
                                                   "birge": pooled.birge},
            "runs": [{"run": r.run, "date": r.date.isoformat(), "method": r.method, "value_m": r.value,
                      "std_m": num(r.std), "before_m": r.before, "flagged": r.flagged, "reason": r.reason,
                      "max_freq_error_before_pct": num(r.max_freq_error_before_pct),
                      "max_freq_error_after_pct": num(r.max_freq_error_after_pct), "boards": list(r.boards),
                      "tests": list(r.tests)} for r in records],
        })
