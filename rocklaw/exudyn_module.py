"""Exudyn, imported for rpdrill: the compiled build the process chose, nothing chosen and nothing hidden here.

Exudyn ships two compiled modules of the same version: ``exudynCPP`` (range checks, any 64-bit CPU)
and ``exudynCPPfast`` (no range checks, AVX2), chosen at its first import by ``sys.exudynFast`` or
``EXUDYN_MODULE=fast`` in the environment (Exudyn's own switches; the fast module says on standard
output that it was loaded). A user's process that imports rpdrill gets the build its own ``import exudyn``
would get. The ``rpdrill`` command chooses the fast one for itself and the workers it starts, in its entry
point (studies.cli.main.console: on the paper scene a step costs about 10 % less, ``python
benchmarks/bench_presets.py --modules``; ``EXUDYN_MODULE=regular`` keeps the regular build). ``FAST``:
which one was loaded.
"""

from __future__ import annotations

import sys

import exudyn as exu

FAST = "exudyn.exudynCPPfast" in sys.modules

__all__ = ["FAST", "exu"]
