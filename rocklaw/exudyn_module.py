"""Exudyn, imported for rpdrill: its build without range checks where the CPU allows it.

Exudyn ships two compiled modules of the same version: ``exudynCPP`` (range checks, any 64-bit CPU)
and ``exudynCPPfast`` (no range checks, AVX2), chosen at its first import by ``sys.exudynFast``. rpdrill
asks for the fast one, which Exudyn loads only on a CPU with AVX2 (else the regular one): on the
paper scene a step costs about 10 % less (``python benchmarks/bench_presets.py --modules``); the
fixed-step solvers (every preset) give the same results to round-off, the automatic-step ones
(dopri5, ode23) accept other steps and agree within their tolerances (docs/accuracy.md). What a user decided stays: exudyn imported before rpdrill,
``sys.exudynFast`` set, or ``EXUDYN_MODULE`` in the environment (``EXUDYN_MODULE=regular``: the
module with range checks). The fast module announces itself on standard output when imported; that
line is dropped (a study's output is its tables). ``FAST``: which one was loaded.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys

if "exudyn" not in sys.modules and not hasattr(sys, "exudynFast") and "EXUDYN_MODULE" not in os.environ:
    sys.exudynFast = True  # Exudyn's own switch, read at its first import
with contextlib.redirect_stdout(io.StringIO()):
    import exudyn as exu

FAST = "exudyn.exudynCPPfast" in sys.modules

__all__ = ["FAST", "exu"]
