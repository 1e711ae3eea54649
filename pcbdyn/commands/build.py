"""``pcbdyn build board.toml``: a board's resonances, mode shapes and effective masses; with
``--uncertainty``, each frequency +- the standard deviation the component library's calibrated
family values give it (:mod:`pcbdyn.problems.uncertainty`)."""

from __future__ import annotations

from pathlib import Path

import click

from .common import done, folder_outputs, input_errors, library_option, solve_structure, step


def analyse(board, config, stds: dict | None = None) -> dict:
    """Build and solve one configuration and print its table; returns what :func:`write_results` writes
    (``stds``: the library's family standard deviations, :func:`pcbdyn.problems.uncertainty.library_uncertainty`,
    propagated to each frequency)."""
    from ..fe.effective_mass import effective_mass
    from ..fe.model import SHELL_TYPES
    from ..report.modes import format_table, free_note, mode_table

    label = config or "base"
    bm, modes, K, M = solve_structure(board, config)
    em = effective_mass(bm.model.nodes, M, modes.shapes)
    mass = float(em.totals[2])
    table = mode_table(bm, modes, em)
    std = None
    reduction = getattr(bm, "reduction_error", lambda *a: None)(modes, K, M)
    if reduction is not None:
        click.echo(f"cards reduced to their interface (Craig-Bampton: {', '.join(f'{c} {k} modes' for c, k in reduction['cards'].items())}): "
                   f"largest frequency error against the full model {reduction['max_error_pct']:.3g} %")
    if stds is not None:
        from ..problems.uncertainty import frequency_std

        std = frequency_std(bm, modes, stds)
        table.insert(2, "+- sd [Hz]", std)
    click.echo(f"\n{board.name} [{label}]: {mass * 1e3:.2f} g, {bm.model.n_dof} DOFs, "
               f"{sum(len(es.conn) for es in bm.model.sets.values() if es.etype in SHELL_TYPES)} shells"
               + (f", {modes.n_rigid} rigid-body modes" if modes.n_rigid else ""))
    warning = empty_band(board, bm, modes, K, M)
    click.echo(f"warning: {warning}\n" if warning else format_table(table) + "\n")
    note = free_note(modes.n_rigid)
    if note and not warning:
        click.echo(f"note: {note}\n")
    shares = None
    if hasattr(bm, "share_groups"):  # a structure in 3-D: each part's share of each mode's kinetic energy
        shares = [dict(zip(bm.share_groups(), map(float, col))) for col in bm.mode_shares(modes.shapes).T]
    summary = {
        "configuration": label,
        "modes": [{"n": k + 1, "frequency_hz": float(f), "effective_mass": fractions, "shape": shape,
                   **({"frequency_std_hz": float(std[k])} if std is not None else {}),
                   **({"shares": shares[k]} if shares is not None else {})}
                  for k, (f, fractions, shape) in enumerate(zip(modes.frequencies, em.as_dicts(), table["shape"]))],
        "mass_kg": mass,
        "centre_of_mass_m": em.centre.tolist(),
        "inertia_kg_m2": dict(zip(("rx", "ry", "rz"), em.totals[3:].tolist())),
        "dofs": int(bm.model.n_dof),
        "rigid_body_modes": int(modes.n_rigid),
        **({"effective_mass_note": note} if note else {}),
        **({"reduction": reduction} if reduction is not None else {}),
        **({"warning": warning} if warning else {}),
    }
    return {"config": config, "model": bm, "modes": modes, "table": table, "summary": summary}


def empty_band(board, bm, modes, K, M) -> str | None:
    """What to say when no elastic mode lies below [analysis] f_max (an empty band is an answer, not an
    error): the first mode above it, solved alone."""
    f_max = board.analysis.f_max
    if modes.frequencies.size or f_max is None:
        return None
    from ..fe.modal import solve_modes

    first = solve_modes(bm.model, n_modes=1, K=K, M=M).frequencies
    above = f"the first is at {first[0]:.4g} Hz" if first.size else "the model has none"
    return f"no mode below [analysis] f_max = {f_max:g} Hz ({above}); raise f_max in {board.path.name} to see modes"


def write_results(board, solved: dict, out: Path, pictures: bool = True) -> None:
    """Write one solved configuration (:func:`analyse`) as CSV, VTU and PNG under ``out``."""
    from ..report.files import write_text
    from ..report.vtu import write_modes_vtu

    config, bm, modes = solved["config"], solved["model"], solved["modes"]
    label = config or "base"
    stem = f"modes_{label}"
    write_text(out / f"{stem}.csv", solved["table"].to_csv(index=False, float_format="%.6g"))
    vtu = out / f"{stem}.vtu"
    write_modes_vtu(vtu, bm.model, modes.frequencies, modes.shapes)
    if pictures:
        from ..report.pictures import mode_pictures

        t0 = step(f"[{label}] rendering {modes.frequencies.size} mode-shape pictures")
        renderer = mode_pictures(vtu, bm.model, modes.frequencies, modes.shapes, out / "png", prefix=stem,
                                 title=f"{board.name} [{label}]", outlines=board.outlines(config))
        done(t0)
        if renderer != "pyvista":
            click.echo("  note: 3-D rendering (pyvista) failed; the 3-D views are drawn by matplotlib", err=True)


def uncertainty_note(stds: dict) -> str:
    if not stds:
        return "note: no part family of this board has a calibrated standard deviation in the library: +- 0"
    return "library uncertainty: " + ", ".join(f"{f} {v * 1e3:.4g} +- {sd * 1e3:.2g} mm ({', '.join(refs)})"
                                               for f, (v, sd, refs) in stds.items())


@click.command("build")
@click.argument("board_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--config", "config", default=None, help="configuration name from [[configurations]]")
@click.option("--all-configs", is_flag=True, help="the base model and every configuration")
@click.option("--no-pictures", is_flag=True, help="skip the PNG mode-shape pictures")
@click.option("--uncertainty", is_flag=True,
              help="frequencies +- the standard deviation the library's calibrated family values give them")
@folder_outputs("folder for modes CSV, VTU (ParaView) and PNG mode shapes",
                "write frequencies, mass and DOF count as JSON", html=True)
@library_option()
def command(board_toml, config, all_configs, out, json_path, no_pictures, html, uncertainty):
    """Predict a board's resonances: frequencies, effective masses, mode shapes."""
    from ..problems import load_structure
    from ..report.files import write_json

    with input_errors():
        board = load_structure(board_toml)
        if config is not None and all_configs:
            raise click.UsageError("give --config NAME or --all-configs, not both")
        configs = [None] + board.configuration_names() if all_configs else [config]
        stds = None
        if uncertainty:
            from ..problems.uncertainty import library_uncertainty

            board, stds = library_uncertainty(board)
            click.echo(uncertainty_note(stds), err=True)
        solved = [analyse(board, c, stds=stds) for c in configs]  # every configuration solves before any file
        results = [r["summary"] for r in solved]
        if out is not None:
            from ..report.manifest import replacing

            with replacing(out, "pcbdyn build") as run:  # the earlier --out stays whole until all is written
                for r in solved:
                    write_results(board, r, run.path, pictures=not no_pictures)
                if html:
                    from ..report.pages import build_page

                    page = run.final(build_page(run.path, board_toml, board, solved))
    if json_path is not None:
        data = dict(results[0]) if len(results) == 1 else {**results[0], "configurations": results}
        data["board"] = board.name
        if stds is not None:
            data["uncertainty"] = {f: {"equivalent_thickness_m": v, "std_m": sd, "parts": refs}
                                   for f, (v, sd, refs) in stds.items()}
        write_json(json_path, data)
    if out is not None:
        if html:
            click.echo(f"page written to {page}", err=True)
        if run.removed:
            click.echo(f"removed {len(run.removed)} file(s) an earlier run wrote to {out}/ and this one did not",
                       err=True)
        click.echo(f"results written to {out}/", err=True)
