"""The ``pcbdyn`` command line: one click group; each command lives in ``pcbdyn/commands/``.

Bad input is reported by the commands themselves (file, field, fix). Anything else that escapes a
command is a bug of pcbdyn: it is reported in one line, with the traceback kept in a log file, never as
a bare traceback; Python warnings are printed as one line each, without internal paths.
"""

import datetime
import tempfile
import traceback
import warnings
from pathlib import Path

import click

from .commands import (build, calibrate, correlate, diagnose, export, identify, import_kicad, library, localize,
                       pretest, shock, simulate_test, study, update, vibe, wedgelock)
from .process import process_settings


def _warning(message, category, filename, lineno, file=None, line=None):
    click.echo(f"warning: {message}", err=True)


class _Group(click.Group):
    def invoke(self, ctx):
        warnings.showwarning = _warning
        try:
            return super().invoke(ctx)
        except (click.exceptions.Exit, click.ClickException, click.exceptions.Abort, SystemExit, KeyboardInterrupt):
            raise
        except Exception as exc:  # a bug: one line and the log, not a traceback
            log = Path(tempfile.gettempdir()) / f"pcbdyn-error-{datetime.datetime.now():%Y%m%d-%H%M%S-%f}.log"
            log.write_text(traceback.format_exc())
            click.echo(f"internal error (a bug in pcbdyn, please report it): {type(exc).__name__}: {exc}; "
                       f"the traceback is in {log}", err=True)
            ctx.exit(3)


@click.group(cls=_Group)
@click.version_option(package_name="pcbdyn")
def main():
    """Vibration of electronic equipment: build FE models of boards and housings, correlate them with
    modal tests, update them and find what they lack."""
    process_settings()


for _module in (build, pretest, simulate_test, correlate, update, wedgelock, localize, study, diagnose, vibe, shock,
                identify, import_kicad, export, calibrate, library):
    main.add_command(_module.command)


if __name__ == "__main__":
    main()
