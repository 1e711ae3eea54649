"""``pcbdyn correlate board.toml test.uff``: pair the test modes with the model's by MAC (thesis eq.
2.3, best combination of close model modes eq. 3.18), COMAC per point (eq. 2.4), table, CSV, JSON
and pictures (MAC matrix, 45-degree frequency plot, shape overlays, COMAC map)."""

from __future__ import annotations

import math
from pathlib import Path

import click
import numpy as np

from .common import PROBE_TOL, done, fail, solve_structure, step

HEADER = ("test mode", "model mode", "f_test [Hz]", "f_model [Hz]", "df [%]", "MAC")


def format_pairs(pairs) -> str:
    """The pair table as fixed-width text (df = (f_model - f_test) / f_test)."""
    rows = ["  ".join(f"{h:>12}" for h in HEADER)]
    for p in pairs:
        rows.append("  ".join([f"{p.test + 1:>12d}", f"{p.model + 1:>12d}", f"{p.f_test:>12.2f}",
                               f"{p.f_model:>12.2f}", f"{p.df_pct:>+12.2f}", f"{p.mac_combined:>12.3f}"]))
    return "\n".join(rows)


def pairs_csv(pairs) -> str:
    lines = [",".join(HEADER) + ",combined with"]
    for p in pairs:
        combo = " ".join(str(c + 1) for c in p.cluster if c != p.model)
        lines.append(f"{p.test + 1},{p.model + 1},{p.f_test!r},{p.f_model!r},{p.df_pct!r},{p.mac_combined!r},{combo}")
    return "\n".join(lines) + "\n"


def comac_csv(labels, xyz, values) -> str:
    lines = ["dof,x [m],y [m],z [m],COMAC"]
    lines += [f"{lab},{x!r},{y!r},{z!r},{float(c)!r}" for lab, (x, y, z), c in zip(labels, xyz.tolist(), values)]
    return "\n".join(lines) + "\n"


def z_rows(test_modes):
    """Rows of the DOFs measured along +-z and their sign (the shape pictures show w only)."""
    d = test_modes.dofs.directions
    rows = np.flatnonzero(np.abs(np.abs(d[:, 2]) - 1.0) < 1e-9)
    return rows, np.sign(d[rows, 2])


def write_outputs(out: Path, board, bm, modes, test_modes, corr) -> list:
    """CSV tables and PNG pictures under ``out``; returns the names written."""
    from ..report import correlation_plots as plots
    from ..report.files import write_text

    pairing = corr.pairing
    written = ["pairs.csv", "comac.csv", "mac_matrix.png", "frequencies.png", "comac.png"]
    write_text(out / "pairs.csv", pairs_csv(pairing.pairs))
    xyz = test_modes.dof_xyz()
    write_text(out / "comac.csv", comac_csv(corr.dof_labels, xyz, corr.comac))
    plots.mac_matrix(out / "mac_matrix.png", pairing.mac, pairing.pairs, test_modes.frequencies, modes.frequencies)
    plots.frequency_plot(out / "frequencies.png", pairing.pairs)
    plots.comac_map(out / "comac.png", board.outline, xyz[:, :2], corr.comac, corr.dof_labels)
    rows, sign = z_rows(test_modes)
    if rows.size:
        model_w = pairing.model_shapes(modes.shapes)[2::6]
        at = pairing.model_shapes(corr.model_at_test)[rows] * sign[:, None]
        test_w = test_modes.shapes[np.ix_(rows, pairing.test_index)] * sign[:, None]
        written += plots.shape_overlays(out, bm.model, board.outline, pairing.pairs, xyz[rows, :2], test_w, at,
                                        model_w)
    return written


@click.command("correlate")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("test_uff", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--config", default=None, help="configuration name from [[configurations]]")
@click.option("--min-mac", type=click.FloatRange(0.0, 1.0), default=0.5, show_default=True,
              help="pairs with a lower MAC are dropped (their test modes are reported unpaired)")
@click.option("--modes", "n_modes", type=click.IntRange(min=1), default=None,
              help="model modes to pair with (default: the board's [analysis] modes, at least 1.5 x the test's)")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="folder for pairs.csv, comac.csv and the PNG pictures")
@click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="write pairs, unpaired test modes and COMAC as JSON")
@click.option("--html", is_flag=True, help="also write the self-contained page report.html in --out")
def command(board_toml, test_uff, config, min_mac, n_modes, out, json_path, html):
    """Correlate a board model with a modal test (UFF): pair table, COMAC, pictures."""
    from ..correlation import correlate
    from ..domain import StructureError
    from ..fe import ModelError
    from ..problems import load_structure
    from ..report.files import write_json
    from ..testdata import TestDataError
    from ..testdata.measured import read_modes

    if html and out is None:
        raise click.UsageError("--html writes report.html into --out: give --out DIR")
    try:
        board = load_structure(board_toml)
        test_modes = read_modes(test_uff)
        board.check_points(test_modes.measured_points(), test_uff)
        n_model = n_modes or max(board.analysis.modes, math.ceil(1.5 * test_modes.n_modes))
        bm, modes, _, _ = solve_structure(board, config, n_modes=n_model)
        t0 = step(f"reading the model at {len(test_modes.dofs)} test DOFs and pairing {test_modes.n_modes} test "
                  f"with {modes.frequencies.size} model modes")
        try:
            corr = correlate(test_modes, bm.model, modes, min_mac=min_mac, tol=PROBE_TOL)
        except ModelError as exc:
            raise TestDataError(f"{test_uff}: the test points do not lie on the model of {board_toml.name}: {exc}")
        done(t0)
    except (StructureError, ModelError, TestDataError) as exc:
        fail(str(exc))
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
    order = np.argsort(corr.comac)
    click.echo(f"COMAC over the pairs: mean {float(np.mean(corr.comac)):.3f}; lowest: "
               + ", ".join(f"{corr.dof_labels[i]} {corr.comac[i]:.3f}" for i in order[:5]))
    written = []
    if out is not None:
        t0 = step(f"writing tables and pictures to {out}")
        written = write_outputs(out, board, bm, modes, test_modes, corr)
        if html:
            from ..report.pages import correlate_page

            written.append(correlate_page(out, board_toml, test_uff, board, label, pairing,
                                          dict(zip(corr.dof_labels, corr.comac.tolist())), written).name)
        done(t0)
        click.echo(f"results written to {out}/ ({len(written)} files)", err=True)
    if json_path is not None:
        data = corr.to_dict()
        data.update({
            "board": board.name, "configuration": label, "test_file": str(test_uff), "min_mac": min_mac,
            "test_frequencies_hz": [float(f) for f in test_modes.frequencies],
            "model_frequencies_hz": [float(f) for f in modes.frequencies],
            "mac_matrix": np.round(pairing.mac, 6).tolist(),
            "files": written,
        })
        write_json(json_path, data)
