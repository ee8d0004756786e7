"""Imported by the process pool's fork server (studies.runners): what every worker needs, loaded once.

The server imports the running command's module first (the command line passes it: the functions
its workers run, with what they import), then this module: the plots' matplotlib and the
formulations, the exact solver's compiled kernels loaded (studies.runners.warm_up), one small figure
drawn (fonts, mathtext and both file formats' writers loaded); the workers forked from it start with
all of it in memory instead of each importing and loading it again. The other commands' modules are
not imported (the advice's and calibration's optimisers, the sensitivity's SALib): a worker that
needs one imports it. Python 3.11's fork server cannot preload the main module itself (it passes the
main path under a key its server does not read); a worker started by ``python -m
rpdrill.studies.cli`` runs that light module again as its main module.
"""

import gc
import io

from .plots.scans import plt
from .runners import warm_up

warm_up()
_figure, _axes = plt.subplots(layout="constrained")
_axes.plot([0.0, 1.0], [0.0, 1.0], marker="o", label="$v_p$ = 1 mm/s")
_axes.set_xlabel("impact frequency $f$ [Hz]")
_axes.legend()
for _format in ("png", "svg"):
    _figure.savefig(io.BytesIO(), format=_format)
plt.close(_figure)
gc.freeze()  # what is loaded stays shared: a collection in a worker would write to every object's page
