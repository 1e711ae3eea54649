"""The ``pcbdyn`` command line: one click group; each command lives in ``pcbdyn/commands/``."""

import click


@click.group()
@click.version_option(package_name="pcbdyn")
def main():
    """Vibration of electronic equipment: build FE models of boards, correlate them with modal
    tests, update them and find what they lack."""


def _register():
    from importlib import import_module

    for name in ("build", "correlate", "simulate_test", "update", "localize", "study", "diagnose"):
        try:
            module = import_module(f"pcbdyn.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"pcbdyn.commands.{name}":
                raise
            continue
        main.add_command(module.command)


_register()
