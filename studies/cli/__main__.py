"""``python -m rpdrill.studies.cli``: the ``rpdrill`` command line."""

from .main import console

console()
