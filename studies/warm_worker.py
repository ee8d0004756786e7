"""Imported by the process pool's fork server (studies.runners): what every worker needs, loaded once.

The server imports every command with what it imports (the study machinery, the formulations, the
plots' matplotlib), loads the exact solver's compiled kernels (studies.runners.warm_up) and draws one
small figure (fonts, mathtext and both file formats' writers loaded); the workers forked from it
start with all of it in memory instead of each importing and loading it again. Python 3.11's fork
server cannot preload the main module itself (it passes the main path under a key its server does
not read), so what a worker's main module imports (the command line, or a benchmark's imports of
the same modules) is imported here; not the command line module itself, which a worker started by
``python -m rpdrill.studies.cli`` runs again as its main module (runpy warns when that module was
imported before).
"""

import gc
import importlib
import io
import pkgutil

from rpdrill.studies import commands
from rpdrill.studies.plots.scans import plt
from rpdrill.studies.runners import warm_up

for _command in pkgutil.iter_modules(commands.__path__):
    importlib.import_module(f"{commands.__name__}.{_command.name}")
warm_up()
_figure, _axes = plt.subplots(layout="constrained")
_axes.plot([0.0, 1.0], [0.0, 1.0], marker="o", label="$v_p$ = 1 mm/s")
_axes.set_xlabel("impact frequency $f$ [Hz]")
_axes.legend()
for _format in ("png", "svg"):
    _figure.savefig(io.BytesIO(), format=_format)
plt.close(_figure)
gc.freeze()  # what is loaded stays shared: a collection in a worker would write to every object's page
