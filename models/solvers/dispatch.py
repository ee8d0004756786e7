"""Running a prepared simulation with the formulation its scene names (models.definition.formulations:
the registry). Each implementation module is imported on first use (the exact and ODE formulations
never import Exudyn) and provides ``simulate(simulation, progress=None)`` (``progress(t)`` as simulated
time advances) and, if it cannot run every scene, ``unsupported(simulation) -> str | None``, there or in
the lighter ``checks`` module the registry names (the exact formulation's exact_system: a study checks
its points before any run without loading the compiled kernels)."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from types import ModuleType
from typing import TYPE_CHECKING

from ..definition.formulations import FORMULATIONS

if TYPE_CHECKING:
    from ..evaluation.results import SimulationResult
    from .simulation import Simulation


def implementation(name: str, checks: bool = False) -> ModuleType:
    """The module of formulation ``name`` in this package (``checks``: its lighter checks module, if any)."""
    formulation = FORMULATIONS[name]
    return importlib.import_module(f".{(checks and formulation.checks) or formulation.module}", __package__)


def simulate(simulation: Simulation, progress: Callable[[float], None] | None = None) -> SimulationResult:
    """Run a prepared simulation with the formulation its scene names."""
    return implementation(simulation.settings.formulation).simulate(simulation, progress)


def unsupported(name: str, simulation: Simulation) -> str | None:
    """Why formulation ``name`` cannot run ``simulation``, or None if it can."""
    check = getattr(implementation(name, checks=True), "unsupported", None)
    return check(simulation) if check else None
