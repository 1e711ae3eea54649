"""The ``pcbdyn`` command line: one click group; each command lives in ``pcbdyn/commands/``."""

import click

from .commands import build, correlate, diagnose, localize, simulate_test, study, update
from .fe.threads import limit_process


@click.group()
@click.version_option(package_name="pcbdyn")
def main():
    """Vibration of electronic equipment: build FE models of boards, correlate them with modal
    tests, update them and find what they lack."""
    limit_process()  # one BLAS and OpenMP thread unless PCBDYN_BLAS_THREADS or the environment say otherwise


for _module in (build, simulate_test, correlate, update, localize, study, diagnose):
    main.add_command(_module.command)
