"""``pcbdyn pretest board.toml|box.toml --out DIR``: plan a modal test with the model before it is run:
sensors (Effective Independence with an AutoMAC guard, uni- or triaxial) and their mass loading, the exciter
(driving-point shares), the suspension of a free structure, and the perturbed configurations (added masses)
that make the parameters identifiable (D-optimal, thesis ch. 6), written as ``[[configurations]]``."""

from __future__ import annotations

from pathlib import Path

import click

from ..domain import MAX_MODES
from .common import done, folder_outputs, input_errors, library_option, number_pair, result_path, step


def _quantities(text: str, unit: str, option: str) -> list:
    from ..units import UnitError, to_si

    try:
        out = [to_si(v.strip(), unit, option) for v in str(text).split(",") if v.strip()]
    except UnitError as exc:
        raise click.BadParameter(str(exc), param_hint=option) from None
    if not out or any(not v > 0 for v in out):
        raise click.BadParameter(f"'{text}' is not a list of positive quantities, e.g. '5 g,10 g,20 g'",
                                 param_hint=option)
    return out


@click.command("pretest")
@click.argument("structure_toml", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--candidates", "candidates_csv", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None, help="candidate points CSV (point,x [mm],y [mm][,z [mm]]); default: a grid over the structure")
@click.option("--spacing", default=None, help="grid spacing, e.g. '13.5 mm' (default: twice the mesh size)")
@click.option("--sensors", "n_sensors", type=click.IntRange(1, 10000), default=None,
              help="sensors to place (default: twice the target modes)")
@click.option("--directions", type=click.Choice(["z", "xyz"]), default=None,
              help="uniaxial along the surface normal (z on a board) or triaxial (default: z on a board, xyz on a box)")
@click.option("--modes", "n_modes", type=click.IntRange(1, MAX_MODES), default=None,
              help="target modes: the first N elastic ones (default: [analysis] modes)")
@click.option("--band", default=None, help="target modes: those in LO,HI Hz instead of --modes")
@click.option("--max-automac", type=click.FloatRange(0.0, 1.0), default=0.25, show_default=True,
              help="bound on the sensors' largest off-diagonal AutoMAC")
@click.option("--sensor-mass", default="2 g", show_default=True, help="mass of one sensor (its loading is reported)")
@click.option("--exciter-share", type=click.FloatRange(0.0, 1.0), default=0.1, show_default=True,
              help="the exciter must drive every target mode at this share of the mode's best point at least")
@click.option("--suspension-share", type=click.FloatRange(0.01, 0.5), default=0.1, show_default=True,
              help="free structures: highest suspension mode as a share of the first elastic one")
@click.option("--parameters", "names", default=None,
              help="parameters the configurations are designed for, comma-separated (default: all [[parameters]])")
@click.option("--configurations", "n_configs", type=click.IntRange(0, 20), default=2, show_default=True,
              help="perturbed configurations to design (0: none; the parameters' 1-sigma with the base test and "
                   "the structure's own configurations is still given)")
@click.option("--masses", default="5 g,10 g,20 g", show_default=True, help="added masses on offer")
@click.option("--noise", default="f=0.2", show_default=True,
              help="frequency noise of the test in percent (uniform bounds, thesis eq. 5.72)")
@click.option("--max-places", type=click.IntRange(1, 100000), default=None,
              help="most candidate places weighed for added masses (evenly thinned; default all usable)")
@folder_outputs("folder for points.csv, candidates.csv, the structure with the designed [[configurations]], "
                "pretest_map.png", "write sensors, exciter, suspension, configurations and identifiability as JSON",
                html=True)
@library_option()
def command(structure_toml, candidates_csv, spacing, n_sensors, directions, n_modes, band, max_automac, sensor_mass,
            exciter_share, suspension_share, names, n_configs, masses, noise, max_places, out, json_path, html):
    """Plan a modal test: sensors, exciter, suspension and perturbed configurations from the model."""
    from ..problems import load_structure
    from ..problems.pretest import choose_exciter, choose_sensors, choose_suspension, mass_loading, pretest_model
    from ..problems.pretest_configs import configuration_entries, design_configurations, write_configurations
    from ..problems.pretest_points import candidate_grid, is_box, read_candidates
    from ..report import pretest_report as rep
    from ..report.files import write_json
    from ..testdata.noise import Noise
    from ..units import to_si

    if n_modes is not None and band is not None:
        raise click.UsageError("give --modes or --band, not both")
    band = number_pair(band, "--band") if band is not None else None
    mass_set = _quantities(masses, "g", "--masses")
    m_sensor = _quantities(sensor_mass, "g", "--sensor-mass")[0]
    try:
        f_pct = Noise.parse(noise).frequency_pct
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="--noise") from None
    if n_configs and not f_pct > 0:
        raise click.BadParameter("designing configurations needs a frequency noise above 0, e.g. f=0.2",
                                 param_hint="--noise")
    with input_errors():
        structure = load_structure(structure_toml)
        box = is_box(structure)
        params = [n.strip() for n in names.split(",") if n.strip()] if names else [p.name for p in structure.parameters]
        known = {p.name for p in structure.parameters}
        if unknown := [n for n in params if n not in known]:
            raise click.BadParameter(f"{unknown} are not [[parameters]] of {structure_toml.name} (known: "
                                     f"{', '.join(sorted(known)) or 'none'})", param_hint="--parameters")
        if candidates_csv is not None:
            cand, source = read_candidates(structure, candidates_csv), {"file": str(candidates_csv)}
        else:
            h = to_si(spacing, "mm", "--spacing") if spacing else 2.0 * structure.mesh_size
            cand, source = candidate_grid(structure, h), {"spacing_mm": h * 1e3}
        t0 = step(f"building {structure_toml.name} and solving its target modes")
        model = pretest_model(structure, params, n_modes, band)
        done(t0)
        triaxial = (directions or ("xyz" if box else "z")) == "xyz"
        n = n_sensors or 2 * model.lam.size
        t0 = step(f"choosing {n} {'triaxial' if triaxial else 'uniaxial'} sensors among {int(cand.usable.sum())} "
                  "candidates (EfI, AutoMAC guard)")
        sensors = choose_sensors(model, cand, n, triaxial, max_automac)
        loading = mass_loading(model, cand.xyz[sensors.chosen], m_sensor)
        exciter = {**choose_exciter(model, cand), "required_share": exciter_share}
        suspension = choose_suspension(model, cand, suspension_share) if model.free else None
        done(t0)
        designed, entries = None, []
        if params and f_pct > 0:
            t0 = step(f"weighing {len(mass_set)} added masses at the candidate places for {n_configs} configurations"
                      if n_configs else "predicting the parameters' 1-sigma with the base test and the own configurations")
            designed = design_configurations(model, cand, mass_set, n_configs, f_pct, max_places,
                                             progress=lambda k, total: k % 20 == 0 and click.echo(
                                                 f"    {k} of {total} places", err=True))
            entries = configuration_entries(structure, cand, designed.chosen)
            done(t0)
        data = rep.pretest_json(structure, model, cand, source, sensors, loading, exciter, suspension, designed,
                                entries, box)
        written = []
        if out is not None:
            from ..report.manifest import replacing

            with replacing(out, "pcbdyn pretest") as run:  # the earlier --out stays whole until all is written
                rep.write_sensor_points(run.path / "points.csv", cand, sensors)
                rep.write_candidates_csv(run.path / "candidates.csv", cand)
                rep.pretest_map(run.path / "pretest_map.png", cand, data, box)
                written = ["points.csv", "candidates.csv", "pretest_map.png"]
                if entries:
                    dst = result_path(run.path, structure_toml, "pretest")
                    write_configurations(structure, entries, dst, load_structure)
                    written.append(dst.name)
                if html:
                    written.append(rep.pretest_page(run.path, structure_toml, data, written).name)
            data["files"] = written
    click.echo("\n" + rep.summary(data))
    if n_configs and not params:
        click.echo(f"no configurations designed: {structure_toml.name} declares no [[parameters]]")
    if out is not None:
        click.echo(f"results written to {out}/ ({len(written)} files)", err=True)
    if json_path is not None:
        write_json(json_path, data)
