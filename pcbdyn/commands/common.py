"""Pieces shared by the commands: progress lines, solving one configuration of a structure, option parsing."""

from __future__ import annotations

import contextlib
import functools
import sys
import time
from pathlib import Path

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


def echo_verdict(what: dict) -> None:
    """A fit's notes (``details``) on stdout and its pairing warnings on stderr, as every fitting command
    prints them."""
    for line in what["details"]:
        click.echo(f"  note: {line}")
    for line in what["warnings"]:
        click.echo(f"warning: {line}", err=True)


def fail(message: str, code: int = 2):
    """Print ``error: message`` on stderr and leave with ``code`` (nothing else is written)."""
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


@contextlib.contextmanager
def input_errors(*more):
    """Bad input met inside (a structure's, test or library file, a quantity, an FE model that cannot be
    solved, updating equations the data leave empty, and the exception classes ``more``) ends the command
    with its one-line message (exit 2). Each reader raises these classes at its boundary, so anything
    else that escapes is a bug (reported as one by the CLI)."""
    from ..components.library import LibraryError
    from ..domain import StructureError
    from ..fe import ModelError
    from ..testdata import TestDataError
    from ..units import UnitError
    from ..updating.errors import UpdatingError

    try:
        yield
    except (StructureError, TestDataError, ModelError, UnitError, LibraryError, UpdatingError, *more) as exc:
        fail(" ".join(str(exc).strip("'\"").split()))  # one line, whatever a library put in the text


def solve_structure(structure, config: str | None, n_modes: int | None = None, f_max: float | None = None,
                    min_modes: int = 0):
    """Build the FE model of one configuration of ``structure`` and solve its modes, with progress.

    Returns (built model, modes, K, M). ``n_modes``/``f_max`` default to the structure's [analysis];
    at least the first ``min_modes`` are returned even when they lie above ``f_max`` (a response to an
    input below the fundamental still needs its modes and static residual).
    """
    from ..fe.assembly import assemble
    from ..fe.modal import solve_modes

    label = config or "base"
    n_modes = structure.analysis.modes if n_modes is None else n_modes
    f_max = structure.analysis.f_max if f_max is None else f_max
    t0 = step(f"[{label}] meshing and building the model")
    pm = structure.build(config)
    done(t0)
    t0 = step(f"[{label}] solving {pm.model.n_dof} DOFs for {n_modes} modes")
    K, M = assemble(pm.model)

    def solve(n, f):
        if hasattr(pm, "solve"):  # a system solves itself: its cards may be reduced (Craig-Bampton)
            return pm.solve(n, f, K=K, M=M)
        return solve_modes(pm.model, n_modes=n, f_max=f, K=K, M=M)

    modes = solve(n_modes, f_max)
    if modes.frequencies.size < min_modes:
        modes = solve(min_modes, None)
    done(t0)
    return pm, modes, K, M


def number_pair(text: str, option: str, unit: str | None = None, counts=(2,)) -> tuple:
    """Two (or as many as ``counts`` allows) comma-separated values such as "135,63.57" (in ``unit``
    when the values carry none, e.g. mm) or "135 mm, 63.57 mm", as SI floats; a clear usage error
    otherwise."""
    from ..units import UnitError, to_si

    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) not in counts or not all(parts):
        raise click.BadParameter(f"'{text}' is not {' or '.join(('two', 'three')[c - 2] for c in counts)} "
                                 "comma-separated values, e.g. '135,63.57'", param_hint=option)
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


def test_arguments(command=None, *, board_required: bool = True):
    """The inputs of a command that fits a structure to its tests: BOARD_TOML, TEST_UFF, NAME=FILE
    configurations, or ``--frequencies FILE.csv`` (``board_required`` False: a command that takes its
    boards from a file instead, as ``calibrate --joint``)."""
    if command is None:
        return functools.partial(test_arguments, board_required=board_required)
    file = click.Path(exists=True, dir_okay=False, path_type=Path)
    for decorate in reversed((
            click.argument("board_toml", required=board_required, type=file),
            click.argument("test_uff", required=False, type=file),
            click.argument("configs", nargs=-1),
            click.option("--frequencies", "freq_csv", type=file, default=None,
                         help="CSV of measured frequencies (configuration, mode, frequency_hz) instead of UFF files; "
                              "test mode n pairs with model mode n"))):
        command = decorate(command)
    return command


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


def measured_configurations(structure, test_uff, extras) -> list:
    """[(configuration name or None, Modes)] of the base test and every NAME=FILE of ``extras``."""
    from ..testdata.measured import read_tests

    return read_tests(structure, test_uff, parse_extra(extras))  # usage errors before any file is read


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


#: command keyword -> the option users write, for messages
OPTION_NAMES = {"json_path": "--json", "out": "--out", "bdf": "--nastran", "chart": "--chart", "plot_path": "--plot"}


def check_writable(path: Path, option: str, folder: bool, shown=None) -> None:
    """A UsageError when ``path`` cannot be written as a file (``folder`` False) or a folder
    (:func:`pcbdyn.atomic.unwritable`). ``shown``: how the message names the path."""
    from ..atomic import unwritable

    if (why := unwritable(path, folder)) is not None:
        raise click.UsageError(f"{option} {path if shown is None else shown}: {why}")


def checked_outputs(folders=("out",), files=("json_path",)):
    """A command decorator: its output options (keywords ``folders`` for folders, ``files`` for files)
    are checked before any work (and ``--html`` needs ``--out``; a folder must be one a run may replace
    whole, :func:`pcbdyn.report.manifest.unreplaceable`), so that a run never fails after its
    computation for want of a place to write; ``--json -`` writes the JSON to the standard output and the
    report to stderr."""

    def decorate(command):
        @functools.wraps(command)
        def run(*args, **kwargs):
            if kwargs.get("html") and kwargs.get("out") is None:
                raise click.UsageError("--html writes report.html into --out: give --out DIR")
            for keys, folder in ((folders, True), (files, False)):
                for key in keys:
                    if kwargs.get(key) is not None and str(kwargs[key]) != "-":
                        check_writable(Path(kwargs[key]), OPTION_NAMES.get(key, f"--{key}"), folder)
            for key in folders:
                if kwargs.get(key) is not None:
                    from ..report.manifest import unreplaceable

                    if (why := unreplaceable(kwargs[key])) is not None:
                        raise click.UsageError(f"{OPTION_NAMES.get(key, f'--{key}')} {kwargs[key]}: {why}")
            if str(kwargs.get("json_path")) == "-":
                from ..report.files import json_to_stdout

                with json_to_stdout():
                    return command(*args, **kwargs)
            return command(*args, **kwargs)

        return run

    return decorate


def result_path(out, source, suffix: str, force: bool = False) -> Path:
    """Where a file pcbdyn names itself goes (``<stem>.<suffix><ext>`` of ``source``, e.g.
    board.updated.toml): into the ``out`` folder when given (the folder holds this run's results), else
    beside ``source``, where an earlier file of that name is kept unless ``force``: the next free
    numbered name is used (board.updated.2.toml)."""
    source = Path(source)
    if out is not None:
        return Path(out) / f"{source.stem}.{suffix}{source.suffix}"
    path = source.with_name(f"{source.stem}.{suffix}{source.suffix}")
    k = 2
    while path.exists() and not force:
        path = source.with_name(f"{source.stem}.{suffix}.{k}{source.suffix}")
        k += 1
    return path


def folder_outputs(out_help: str, json_help: str, html: bool = False, force: str | None = None):
    """The output options of a command that writes into a folder: ``--out`` (``out_help``), ``--force``
    (when ``force`` says what it replaces), ``--json`` (``json_help``; ``-`` for the standard output) and,
    with ``html``, ``--html``; all checked before any work (:func:`checked_outputs`)."""

    def decorate(command):
        command = checked_outputs()(command)
        if html:
            command = click.option("--html", is_flag=True, help="also write the self-contained page report.html in "
                                                                "--out")(command)
        command = click.option("--json", "json_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
                               help=f"{json_help} ('-': standard output)")(command)
        if force:
            command = click.option("--force", is_flag=True, help=force)(command)
        return click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
                            help=out_help)(command)

    return decorate


def library_option(required: bool = False, keep: bool = False):
    """The ``--library DIR`` option of every command that loads a board: DIR is searched first for part
    families while the command runs (:func:`pcbdyn.components.library.chosen`), before a ``library/``
    beside the board, PCBDYN_LIBRARY and the shipped library. ``keep``: the command also receives
    ``library`` (the folder ``pcbdyn calibrate`` writes)."""

    def decorate(f):
        @functools.wraps(f)
        def wrapper(*args, library=None, **kwargs):
            from ..components.library import chosen

            with chosen([] if library is None else [library]):
                return f(*args, **({"library": library} if keep else {}), **kwargs)

        help_text = ("component library folder, searched first for part families (then a library/ beside the "
                     "board, PCBDYN_LIBRARY, the shipped library)")
        return click.option("--library", type=click.Path(file_okay=False, path_type=Path), required=required,
                            default=None, help=help_text)(wrapper)

    return decorate


def units_option(command):
    """The ``--units`` option of every command that reads test data: the length unit of UFF files that state
    none (no dataset 164), for the whole command (:func:`pcbdyn.testdata.uff_geometry.stated_units`); a file
    without one whose grid is too wide for metres is refused, naming this option."""
    from ..units import LENGTHS

    @functools.wraps(command)
    def wrapper(*args, units=None, **kwargs):
        from ..testdata.uff_geometry import stated_units

        with stated_units(units):
            return command(*args, **kwargs)

    return click.option("--units", type=click.Choice(list(LENGTHS)), default=None,
                        help="length unit of test files (UFF) that state none (no dataset 164); default m")(wrapper)
