"""The formulations of the same model, by name: one registry that every command dispatches through.

``exudyn``: the multibody model (default). ``ode``: the paper's Eq. 4 as an event-located SciPy
ODE (independent cross-check). ``exact``: the piecewise-linear model propagated by matrix
exponentials between located switches (the reference and the fast path for large sweeps).

A scene chooses one in ``solver.formulation`` and gives its options next to it (the keys listed
here; a key of another formulation is an error). Each implementation module is imported on first
use (the exact and ODE formulations never import Exudyn) and provides ``simulate(simulation,
progress=None)`` (``progress(t)`` is called as simulated time advances) and, if it cannot run every
scene, ``unsupported(simulation) -> str | None``, there or in a lighter ``checks`` module that the
registry names (the exact formulation's, models.solvers.exact_system: a study checks its points before any
run without loading the compiled kernels).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..evaluation.results import SimulationResult
    from ..solvers.simulation import Simulation

# accuracy tiers that every formulation resolves into its own settings (models.evaluation.solver_settings)
PRESETS = ("fast", "standard", "reference")
DEFAULT_PRESET = "standard"
EXUDYN_SOLVERS = ("rk67", "rk44", "rk33", "explicit_midpoint", "explicit_euler", "generalized_alpha",
                  "trapezoidal_index2", "dopri5", "ode23")
AUTOMATIC_STEP_SOLVERS = ("dopri5", "ode23")
ODE_METHODS = ("DOP853", "Radau", "LSODA")


@dataclass(frozen=True)
class Formulation:
    """A formulation: its implementation module (relative to this package), the ``solver`` keys it takes, and the module with its
    ``unsupported`` check when that is lighter to import than the implementation (``checks``)."""

    name: str
    module: str
    option_keys: tuple[str, ...]
    summary: str
    checks: str | None = None

    def implementation(self) -> ModuleType:
        return importlib.import_module(self.module, __package__)


FORMULATIONS: dict[str, Formulation] = {f.name: f for f in (
    Formulation("exudyn", "..solvers.exudyn_model",
                ("type", "step_s", "spectral_radius", "relative_tolerance", "absolute_tolerance"),
                "the Exudyn multibody model"),
    Formulation("exact", "..solvers.exact_model",
                ("sample_interval_s", "min_switch_interval_s", "max_switches_per_blow"),
                "exact piecewise-linear propagation between located switches", checks="..solvers.exact_system"),
    Formulation("ode", "..solvers.ode_model",
                ("method", "relative_tolerance", "absolute_tolerance", "sample_interval_s"),
                "the paper's Eq. 4 as an event-located SciPy ODE"),
)}
COMMON_SOLVER_KEYS = ("formulation", "preset", "end_time_s", "output_interval_s")


def simulate(simulation: Simulation, progress: Callable[[float], None] | None = None) -> SimulationResult:
    """Run a prepared simulation with the formulation its scene names."""
    return FORMULATIONS[simulation.settings.formulation].implementation().simulate(simulation, progress)


def unsupported(name: str, simulation: Simulation) -> str | None:
    """Why formulation ``name`` cannot run ``simulation``, or None if it can."""
    formulation = FORMULATIONS[name]
    module = importlib.import_module(formulation.checks or formulation.module, __package__)
    check = getattr(module, "unsupported", None)
    return check(simulation) if check else None
