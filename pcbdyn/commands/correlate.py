"""``pcbdyn correlate board.toml test.uff``: pair the test modes with the model's by MAC (thesis eq.
2.3, best combination of close model modes eq. 3.18), COMAC per point (eq. 2.4), table, CSV, JSON
and pictures (MAC matrix, 45-degree frequency plot, shape overlays, COMAC map)."""

from __future__ import annotations

import math
from pathlib import Path

import click

from ..domain import MAX_MODES
from .common import PROBE_TOL, done, fail, folder_outputs, input_errors, library_option, solve_structure, step, units_option

@click.command("correlate")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("test_uff", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--config", default=None, help="configuration name from [[configurations]]")
@click.option("--min-mac", type=click.FloatRange(0.0, 1.0), default=0.5, show_default=True,
              help="pairs with a lower MAC are dropped (their test modes are reported unpaired)")
@click.option("--modes", "n_modes", type=click.IntRange(1, MAX_MODES), default=None,
              help="model modes to pair with (default: the board's [analysis] modes, at least 1.5 x the test's)")
@folder_outputs("folder for pairs.csv, comac.csv and the PNG pictures",
                "write pairs, unpaired test modes and COMAC as JSON", html=True)
@library_option()
@units_option
def command(board_toml, test_uff, config, min_mac, n_modes, out, json_path, html):
    """Correlate a structure's model (board.toml or box.toml, one configuration) with a modal test (UFF with
    mode shapes): pairs by MAC, frequency differences, COMAC, pictures."""
    from ..correlation import correlate
    from ..fe import ModelError
    from ..problems import load_structure
    from ..report.correlation_report import comac_line, format_pairs, write_outputs
    from ..report.files import write_json
    from ..testdata import TestDataError
    from ..testdata.measured import read_test

    with input_errors():
        board = load_structure(board_toml)
        test = read_test(test_uff)
        test_modes = test.modes
        board.check_points(test_modes.measured_points(), test_uff)
        n_model = n_modes or min(MAX_MODES, max(board.analysis.modes, math.ceil(1.5 * test_modes.n_modes)))
        bm, modes, _, _ = solve_structure(board, config, n_modes=n_model)
        t0 = step(f"reading the model at {len(test_modes.dofs)} test DOFs and pairing {test_modes.n_modes} test "
                  f"with {modes.frequencies.size} model modes")
        try:
            corr = correlate(test_modes, bm.model, modes, min_mac=min_mac, tol=PROBE_TOL)
        except ModelError as exc:
            raise TestDataError(f"{test_uff}: the test points do not lie on the model of {board_toml.name}: {exc}")
        done(t0)
    pairing = corr.pairing
    if not pairing.pairs:
        best = float(pairing.mac.max()) if pairing.mac.size else 0.0
        fail(f"no mode of {test_uff} pairs with a mode of {board_toml.name} (best MAC {best:.2f} < --min-mac "
             f"{min_mac:g}); check that the test points are in the board frame and units, that test and model are "
             "the same board and configuration (--config), or lower --min-mac")
    label = config or "base"
    click.echo(f"\n{board.name} [{label}] against {test_uff.name}: {len(pairing.pairs)} pair(s) of "
               f"{test_modes.n_modes} test and {modes.frequencies.size} model modes (min MAC {min_mac:g})")
    click.echo(format_pairs(pairing.pairs))
    if pairing.unpaired_test:
        click.echo(f"unpaired test modes: {', '.join(str(i + 1) for i in pairing.unpaired_test)}")
    click.echo(comac_line(corr))
    for line in pairing.warnings(modes.frequencies):
        click.echo(f"warning: {line}", err=True)
    written = []
    if out is not None:
        from ..report.manifest import replacing

        t0 = step(f"writing tables and pictures to {out}")
        with replacing(out, "pcbdyn correlate") as run:  # the earlier --out stays whole until all is written
            written = write_outputs(run.path, board, bm, modes, test_modes, corr, test.wireframe)
            if html:
                from ..report.pages import correlate_page

                written.append(correlate_page(run.path, board_toml, test_uff, board, config, corr, written, bm,
                                              modes, test_modes).name)
        done(t0)
        click.echo(f"results written to {out}/ ({len(written)} files)", err=True)
    if json_path is not None:
        data = corr.to_dict()
        data.update({
            "board": board.name, "configuration": label, "test_file": str(test_uff), "min_mac": min_mac,
            "test_frequencies_hz": [float(f) for f in test_modes.frequencies],
            "model_frequencies_hz": [float(f) for f in modes.frequencies],
            "mac_matrix": pairing.mac.round(6).tolist(),
            "automac": pairing.automac.round(6).tolist(),
            "files": written,
        })
        write_json(json_path, data)
