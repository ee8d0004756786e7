"""The ``rpdrill`` command line as the tests run it: ``main(argv)`` in this process, returning the exit
status (the program's entry point, imported here once so that the tests do not depend on where it lives)."""

from rpdrill.studies.cli.main import COMMANDS, main

UNITS = ("rpdrill.studies.cli.main",)  # the program's entry point (pyproject.toml's [project.scripts]), in-process

__all__ = ["COMMANDS", "main"]
