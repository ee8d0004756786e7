"""Exudyn, imported for rpdrill: the regular build, or the build without range checks where rpdrill owns the process.

Exudyn ships two compiled modules of the same version: ``exudynCPP`` (range checks, any 64-bit CPU)
and ``exudynCPPfast`` (no range checks, AVX2), chosen at its first import by ``sys.exudynFast``.
Importing rpdrill never chooses for a user: a user's ``import exudyn`` gets the build it would get
without rpdrill. Only a process rpdrill owns opts in, by :func:`rocklaw.exudyn_build.use_fast_build` before anything imports
Exudyn: the ``rpdrill`` command does (studies.cli), and its worker processes inherit the choice through
``EXUDYN_MODULE=fast`` in their environment. Exudyn loads the fast module only on a CPU with AVX2
(else the regular one): on the paper scene a step costs about 10 % less (``python
benchmarks/bench_presets.py --modules``); the fixed-step solvers (every preset) give the same results
to round-off, the automatic-step ones (dopri5, ode23) accept other steps and agree within their
tolerances (docs/accuracy.md). What a user decided stays: exudyn imported first, ``sys.exudynFast``
set, or ``EXUDYN_MODULE=regular``. The fast module announces itself on standard output when
imported; that line is dropped (a study's output is its tables). ``FAST``: which one was loaded.
"""

from __future__ import annotations

import contextlib
import io
import sys

from .exudyn_build import fast_build_wanted

if fast_build_wanted() and "exudyn" not in sys.modules and not hasattr(sys, "exudynFast"):
    sys.exudynFast = True  # Exudyn's own switch, read at its first import
with contextlib.redirect_stdout(io.StringIO()):
    import exudyn as exu

FAST = "exudyn.exudynCPPfast" in sys.modules

__all__ = ["FAST", "exu"]
