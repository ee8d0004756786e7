"""The module of a formulation (models.definition.formulations: the registry), imported on first use
(the exact and ODE formulations never import Exudyn). Each provides ``simulate(simulation,
progress=None)`` (``progress(t)`` as simulated time advances) and, if it cannot run every scene,
``unsupported(simulation) -> str | None``, there or in the lighter ``checks`` module the registry names
(the exact formulation's exact_system: a study checks its points before any run without loading the
compiled kernels); models.solvers.simulation calls them (``Simulation.solve``, ``unsupported``)."""

from __future__ import annotations

import importlib
from types import ModuleType

from ..definition.formulations import FORMULATIONS


def implementation(name: str, checks: bool = False) -> ModuleType:
    """The module of formulation ``name`` in this package (``checks``: its lighter checks module, if any)."""
    formulation = FORMULATIONS[name]
    return importlib.import_module(f".{(checks and formulation.checks) or formulation.module}", __package__)
