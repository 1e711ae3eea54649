"""The ``pcbdyn`` command line: one click group; each command lives in ``pcbdyn/commands/``."""

import click

from .commands import (build, correlate, diagnose, export, identify, import_kicad, localize, simulate_test, study,
                       update, vibe)


@click.group()
@click.version_option(package_name="pcbdyn")
def main():
    """Vibration of electronic equipment: build FE models of boards, correlate them with modal
    tests, update them and find what they lack."""


for _module in (build, simulate_test, correlate, update, localize, study, diagnose, vibe, identify, import_kicad,
                export):
    main.add_command(_module.command)
