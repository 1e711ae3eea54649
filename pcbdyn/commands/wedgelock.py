"""``pcbdyn wedgelock board.toml test.uff [c2=test2.uff ...]``: the two-step wedge-lock fit of thesis
section 7.4 (see :mod:`pcbdyn.problems.wedgelock`). Step 1 correlates the board with every wedge_lock
guide hinged and clamped; clamped is accepted when its errors are within the tolerance (the test noise and
the model's mesh error, or ``--tol``). Otherwise step 2 fits the guides' rotational stiffness on a log scale
(one shared, or one per guide with ``--per-guide`` or when the data show the guides differ) and keeps the
springs only if they explain the test significantly better than clamped guides. With ``--frequencies
FILE.csv`` (configuration, mode, frequency_hz) test mode n pairs with model mode n.

Writes the tables (extremes, stiffness, before/after), the iteration history and the frequencies
against the stiffness (``--out``), ``<board>.updated.toml`` with the fitted stiffness (springs whose fit
converged only, unless ``--force``: into ``--out``, else beside the board, never over an earlier one
unless ``--force``), and ``--json``."""

from __future__ import annotations

import click

from .common import (PROBE_TOL, done, fail, folder_outputs, input_errors, library_option, parse_extra, parse_noise, result_path, step,
                     test_arguments, units_option)


@click.command("wedgelock")
@test_arguments
@click.option("--per-guide/--shared", "per_guide", default=None,
              help="one stiffness per guide, or one shared by all (default: shared, unless the data show the "
                   "guides differ)")
@click.option("--tol", "tol_pct", type=click.FloatRange(min=0.0, min_open=True), default=None,
              help="accept clamped guides when every paired mode is within this percentage (default: what the "
                   "test noise and the model's mesh error explain)")
@click.option("--noise", default=None,
              help="the test's noise in percent, e.g. f=0.2,shape=2 (uniform bounds; the frequency noise sets the "
                   "tolerance and the weights, the shape noise weighs the shapes when they join the fit; default "
                   "f=0.2,shape=2)")
@click.option("--min-mac", type=click.FloatRange(0.0, 1.0), default=0.5, show_default=True,
              help="pairs with a lower MAC are dropped")
@click.option("--mesh-size", default=None, help="override board.mesh_size, e.g. '10 mm'")
@click.option("--max-iter", type=click.IntRange(min=1), default=20, show_default=True)
@folder_outputs("folder for board.updated.toml (springs only), the tables and pictures (default: board.updated.toml "
                "beside the board)", "write the extremes, the decision, the stiffness, before/after and the history as "
                "JSON", force="replace an earlier board.updated.toml beside the board (default: a numbered name), "
                              "and write it even when the spring fit did not converge")
@library_option()
@units_option
def command(board_toml, test_uff, configs, freq_csv, per_guide, tol_pct, noise, min_mac, mesh_size, max_iter, out,
            force, json_path):
    """Fit wedge-lock guides in two steps: hinged and clamped extremes, then rotational springs. TEST_UFF
    is the base configuration's test, NAME=FILE each perturbed configuration's of board.toml (e.g.
    c2=test2.uff); or measured frequencies (--frequencies CSV)."""
    from ..problems import load_structure
    from ..problems.wedgelock import fit_wedge_locks
    from ..report import wedgelock_report as rep
    from ..report.files import write_json, write_text
    from ..testdata.measured import read_frequency_table, read_tests
    from ..units import to_si

    if (test_uff is None) == (freq_csv is None):
        fail("give either TEST_UFF (and NAME=FILE for other configurations) or --frequencies FILE.csv")
    freq_noise, shape_noise = parse_noise(noise)
    with input_errors():
        board = load_structure(board_toml)
        ms = to_si(mesh_size, "mm", "--mesh-size") if mesh_size else None
        if freq_csv is not None:
            tests = read_frequency_table(freq_csv, board)
        else:
            files = [(None, test_uff)] + parse_extra(configs)
            tests = read_tests(board, test_uff, files[1:])
            for (_, t), (_, path) in zip(tests, files):
                board.check_points(t.measured_points(), path)
        t0 = step("fitting the wedge-lock guides")
        result = fit_wedge_locks(board, tests, per_guide=per_guide, tol_pct=tol_pct, noise_pct=freq_noise,
                                 shape_noise_pct=shape_noise, mesh_size=ms, min_mac=min_mac, probe_tol=PROBE_TOL, max_iter=max_iter,
                                 progress=lambda msg: click.echo(f"    {msg}", err=True))
        done(t0)
    d = result.to_dict()
    before, after = result.before_after()
    tables = {"extremes.txt": "\n\n".join(rep.format_extreme(k, d["extremes"][k], d["tolerance_pct"])
                                          for k in ("hinged", "clamped")),
              "stiffness.txt": rep.format_summary(d) + "\n\n" + rep.format_stiffness(d["k_rot"]),
              "correlation.txt": rep.format_before_after(d, before, after)}
    click.echo(f"\n{board.name}: guides {', '.join(result.guides)}")
    for text in tables.values():
        click.echo("\n" + text)
    for line in d["warnings"]:
        click.echo(f"warning: {line}", err=True)
    status = next((f["status"] for f in d.get("fits", {}).values() if f["chosen"]), None)
    springs = d["decision"] == "springs" and (status == "converged" or force)
    if d["decision"] == "springs" and not springs:
        click.echo(f"\nno updated board written: the spring fit did not converge ({status}); --force writes it anyway",
                   err=True)
    if out is None:
        d["updated_board"] = _updated(result, result_path(None, board_toml, "updated", force)) if springs else None
    else:
        from ..report.manifest import replacing

        with replacing(out, "pcbdyn wedgelock") as run:  # the earlier --out stays whole until all is written
            d["updated_board"] = _updated(result, result_path(run.path, board_toml, "updated"), run.final) \
                if springs else None
            for name, text in tables.items():
                write_text(run.path / name, text + "\n")
            if d["history"]:
                rep.plot_history(run.path / "history.png", d)
            if "scan" in d:
                rep.plot_frequencies(run.path / "frequencies_vs_k.png", d)
        click.echo(f"results written to {out}/", err=True)
    if json_path is not None:
        write_json(json_path, d)


def _updated(result, path, final=lambda p: p) -> str | None:
    """The board with the fitted springs written to ``path``; where it ends up (``final`` of the path
    written), or None when its springs cannot be written back (said why)."""
    from ..domain import StructureError

    try:
        dst = final(result.chosen.problem.write_updated(result.chosen.result.p, path, source="pcbdyn wedgelock"))
    except StructureError as exc:
        click.echo(f"note: the updated board was not written ({exc}); the fitted stiffness is in the table above and "
                   "in the JSON (k_rot): give each guide its own [[parameters]] entry, or set k_rot in board.toml by "
                   "hand", err=True)
        return None
    click.echo(f"\nupdated board written to {dst}", err=True)
    return str(dst)
