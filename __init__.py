"""rpdrill: multibody simulation of rotary-percussive rock drilling on Exudyn.

The public API (every name documented with an example in ``docs/api.md``)::

    import rpdrill
    scene = rpdrill.load_scene("studies/scenes/paper_base.yaml")
    scene = scene.with_({"impact.frequency_hz": 70.0, "solver.formulation": "exact"})
    result = rpdrill.simulate(scene)
    result.metrics["penetration_rate_m_per_s"]
    table = rpdrill.run_study(rpdrill.load_study("studies/paper/frequency_scan.yaml"), workers=2)
    rpdrill.crosscheck(scene).passed   # Exudyn against the paper's Eq. 4 as an ODE, first 20 blows
    rpdrill.advise(scene, {"impact.frequency_hz": (45, 70), "feed.force_n": (10e3, 30e3)})[0].best

The package's folders: ``rocklaw`` (the rock contact laws), ``models`` (the drill models and their
three formulations), ``studies`` (YAML inputs, scans, analyses, reports and the command line);
dependencies run one way, studies -> models -> rocklaw (``docs/architecture.md``).
"""

from typing import Any

from .models.definition.scene import Scene
from .models.definition.validation import InputError
from .models.evaluation.run_result import Result
from .models.evaluation.stability import SimulationFailed
from .studies.advice.advice_run import Advice, AdviceSearch
from .studies.advice.advice_run import advise_scene as advise
from .studies.api import load_scene, load_study, run_study, save_result, simulate, table_frame
from .studies.crosscheck.crosscheck_run import Crosscheck, crosscheck
from .studies.runtime.budgets import BudgetError
from .studies.scan.study import Study

# Names that load Exudyn (or matplotlib) when first used, not at ``import rpdrill``: so that the command
# line can still choose Exudyn's build (rocklaw.exudyn_build) and a user's ``import exudyn`` gets the
# regular one.
_LAZY = {"build_exudyn": ("models.solvers.exudyn_model", "build_exudyn"),
         "ExudynModel": ("models.solvers.exudyn_model", "ExudynModel"),
         "draw": ("studies.figures.drill_drawing", "draw"),
         "write_animation": ("studies.figures.drill_animation", "write_animation"),
         "view_solution": ("studies.figures.drill_animation", "view_solution")}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        module, attribute = _LAZY[name]
        return getattr(importlib.import_module(f".{module}", __name__), attribute)
    raise AttributeError(f"module 'rpdrill' has no attribute {name!r}")


__all__ = ["Advice", "AdviceSearch", "BudgetError", "Crosscheck", "ExudynModel", "InputError", "Result", "Scene", "SimulationFailed", "Study", "advise", "build_exudyn",
           "crosscheck", "draw", "load_scene", "load_study", "run_study", "save_result", "simulate", "table_frame", "view_solution",
           "write_animation"]
