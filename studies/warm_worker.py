"""Imported by the process pool's fork server (studies.runners): what every worker needs, loaded once.

The server imports rpdrill's study machinery, both formulations and the plots' matplotlib, and loads
the exact solver's compiled kernels (studies.runners.warm_up); the workers forked from it start with
all of it in memory instead of each importing and loading it again.
"""

from rpdrill.studies.plots import scans
from rpdrill.studies.runners import warm_up

warm_up()

__all__ = ["scans"]
