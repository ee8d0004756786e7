"""Which compiled Exudyn module a process loads: the choice, without importing Exudyn (rocklaw.exudyn_module).

:func:`use_fast_build` opts a process rpdrill owns (the ``rpdrill`` command) and the processes it starts
into Exudyn's build without range checks, through ``EXUDYN_MODULE=fast`` in the environment; a user's
own process that imports rpdrill keeps the build its ``import exudyn`` would get.
"""

from __future__ import annotations

import os

ENVIRONMENT = "EXUDYN_MODULE"  # "fast": the build without range checks; "regular" (or unset): with them


def use_fast_build() -> None:
    """Opt this process and its children into the fast build; call it before anything imports Exudyn.
    ``EXUDYN_MODULE`` already in the environment (``regular``) wins."""
    os.environ.setdefault(ENVIRONMENT, "fast")


def fast_build_wanted() -> bool:
    """Whether this process opted in (:func:`use_fast_build`, or ``EXUDYN_MODULE=fast``)."""
    return os.environ.get(ENVIRONMENT) == "fast"
