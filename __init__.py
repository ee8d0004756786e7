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
    rpdrill.calibrate("studies/paper/calibration.yaml", out="runs/calibration").best
    rpdrill.sensitivity("studies/paper/sensitivity.yaml").summary
    rpdrill.accuracy("studies/accuracy_studies/paper_base.yaml").pareto
    rpdrill.reproduce(out="runs/reproduction").passed
    rpdrill.rotation_report("runs/rotation").ridge

Every command of the ``rpdrill`` program is one of these calls. The package's folders: ``rocklaw`` (the
rock contact laws), ``models`` (the drill models and their three formulations), ``studies`` (YAML
inputs, scans, analyses, reports and the command line); dependencies run one way, studies -> models ->
rocklaw (``docs/architecture.md``).
"""

from typing import Any

from .models.definition.scene import Scene
from .models.definition.validation import InputError
from .models.evaluation.run_result import Result
from .models.evaluation.stability import SimulationFailed
from .studies.api import load_scene, load_study, run_study, save_result, simulate, table_frame
from .studies.runtime.budgets import Budget, BudgetError
from .studies.scan.study import Study

# Names loaded when first used, not at ``import rpdrill``: the analyses (SciPy's optimizers, SALib), Exudyn
# (a user's ``import exudyn`` gets the build it would get without rpdrill) and matplotlib. ``import
# rpdrill`` and every command load only what they use.
_LAZY = {"build_exudyn": ("models.solvers.exudyn_model", "build_exudyn"),
         "ExudynModel": ("models.solvers.exudyn_model", "ExudynModel"),
         "draw": ("studies.figures.drill_drawing", "draw"),
         "write_animation": ("studies.figures.drill_animation", "write_animation"),
         "view_solution": ("studies.figures.drill_animation", "view_solution"),
         "advise": ("studies.advice.advice_run", "advise_scene"),
         "Advice": ("studies.advice.advice_run", "Advice"),
         "AdviceSearch": ("studies.advice.advice_run", "AdviceSearch"),
         "crosscheck": ("studies.crosscheck.crosscheck_run", "crosscheck"),
         "Crosscheck": ("studies.crosscheck.crosscheck_run", "Crosscheck"),
         "calibrate": ("studies.calibration.calibration_run", "calibrate"),
         "CalibrationResult": ("studies.calibration.calibration_run", "CalibrationResult"),
         "sensitivity": ("studies.sensitivity.sensitivity_run", "sensitivity"),
         "SensitivityResult": ("studies.sensitivity.sensitivity_run", "SensitivityResult"),
         "accuracy": ("studies.accuracy.accuracy_run", "accuracy"),
         "AccuracyResult": ("studies.accuracy.accuracy_run", "AccuracyResult"),
         "reproduce": ("studies.pages.reproduction_run", "reproduce"),
         "ReproductionResult": ("studies.pages.reproduction_run", "ReproductionResult"),
         "rotation_report": ("studies.pages.rotation_note", "rotation_report"),
         "RotationReport": ("studies.pages.rotation_note", "RotationReport")}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        module, attribute = _LAZY[name]
        return getattr(importlib.import_module(f".{module}", __name__), attribute)
    raise AttributeError(f"module 'rpdrill' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = ["AccuracyResult", "Advice", "AdviceSearch", "Budget", "BudgetError", "CalibrationResult", "Crosscheck", "ExudynModel",
           "InputError", "ReproductionResult", "Result", "RotationReport", "Scene", "SensitivityResult",
           "SimulationFailed", "Study", "accuracy", "advise", "build_exudyn", "calibrate", "crosscheck", "draw",
           "load_scene", "load_study", "reproduce", "rotation_report", "run_study", "save_result", "sensitivity",
           "simulate", "table_frame", "view_solution", "write_animation"]
