"""rpdrill: multibody simulation of rotary-percussive rock drilling on Exudyn.

The public API (every name with an example in ``docs/api.md``; each name's docstring, in numpydoc style, is
the API reference of the documentation site, ``docs/reference/index.md``)::

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
    rpdrill.drill_hole("holes/top_hammer_30m", out="runs/hole").summary["total_time_s"]

Every command of the ``rpdrill`` program is one of these calls. The package's folders: ``rocklaw`` (the
rock contact laws), ``models`` (the drill models and their three formulations), ``studies`` (YAML
inputs, scans, analyses, reports and the command line); dependencies run one way, studies -> models ->
rocklaw (``docs/architecture.md``).
"""

from typing import TYPE_CHECKING as _TYPE_CHECKING
from typing import Any as _Any

# Every public name is imported when first used, not at ``import rpdrill``: the ``rpdrill`` program starts
# (and takes its Ctrl-C handler, studies.cli.main.console) before NumPy, pydantic or Exudyn load; the program
# chooses Exudyn's build in its entry point, and a user's ``import exudyn`` gets the regular one.
_LAZY = {"Scene": ("models.definition.scene", "Scene"),
         "InputError": ("models.definition.validation", "InputError"),
         "extension": ("models.definition.own_code", "extension"),
         "RockLaw": ("rocklaw.base", "RockLaw"),
         "Result": ("models.evaluation.run_result", "Result"),
         "Regime": ("models.evaluation.run_record", "Regime"),
         "EnergyAccount": ("models.evaluation.energy", "EnergyAccount"),
         "SimulationFailed": ("models.evaluation.stability", "SimulationFailed"),
         "StepLimitWarning": ("models.evaluation.stability", "StepLimitWarning"),
         "UnsettledWarning": ("models.evaluation.run_status", "UnsettledWarning"),
         "ExudynMessage": ("models.solvers.exudyn_messages", "ExudynMessage"),
         "WaveStepRounded": ("models.waves.steps", "WaveStepRounded"),
         "Advice": ("studies.advice.advice_run", "Advice"),
         "AdviceSearch": ("studies.advice.advice_run", "AdviceSearch"),
         "advise": ("studies.advice.advice_run", "advise_scene"),
         "drill_hole": ("studies.hole.drill", "drill_hole"),
         "HoleResult": ("studies.hole.hole_run", "HoleResult"),
         "load_scene": ("studies.api", "load_scene"),
         "load_study": ("studies.api", "load_study"),
         "run_study": ("studies.api", "run_study"),
         "shipped_files": ("studies.inputs.shipped", "shipped_files"),
         "ShippedFile": ("studies.inputs.shipped", "ShippedFile"),
         "save_result": ("studies.api", "save_result"),
         "simulate": ("studies.api", "simulate"),
         "table_frame": ("studies.api", "table_frame"),
         "Crosscheck": ("studies.crosscheck.crosscheck_run", "Crosscheck"),
         "crosscheck": ("studies.crosscheck.crosscheck_run", "crosscheck"),
         "Budget": ("studies.runtime.budgets", "Budget"),
         "RunOptions": ("studies.runtime.run_options", "RunOptions"),
         "BudgetError": ("studies.runtime.budgets", "BudgetError"),
         "Study": ("studies.scan.study", "Study"),
         "build_exudyn": ("models.solvers.exudyn_model", "build_exudyn"),
         "ExudynModel": ("models.solvers.exudyn_model", "ExudynModel"),
         "draw": ("studies.drawings.drill_drawing", "draw"),
         "write_animation": ("studies.drawings.drill_animation", "write_animation"),
         "view_solution": ("studies.drawings.drill_animation", "view_solution"),
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

if _TYPE_CHECKING:  # the names as type checkers and editors see them
    from .models.definition.own_code import extension
    from .models.definition.scene import Scene
    from .models.definition.validation import InputError
    from .models.evaluation.energy import EnergyAccount
    from .models.evaluation.run_record import Regime
    from .models.evaluation.run_result import Result
    from .models.evaluation.run_status import UnsettledWarning
    from .models.evaluation.stability import SimulationFailed, StepLimitWarning
    from .models.solvers.exudyn_messages import ExudynMessage
    from .models.solvers.exudyn_model import ExudynModel, build_exudyn
    from .models.waves.steps import WaveStepRounded
    from .rocklaw.base import RockLaw
    from .studies.accuracy.accuracy_run import AccuracyResult, accuracy
    from .studies.advice.advice_run import Advice, AdviceSearch
    from .studies.advice.advice_run import advise_scene as advise
    from .studies.api import load_scene, load_study, run_study, save_result, simulate, table_frame
    from .studies.calibration.calibration_run import CalibrationResult, calibrate
    from .studies.crosscheck.crosscheck_run import Crosscheck, crosscheck
    from .studies.drawings.drill_animation import view_solution, write_animation
    from .studies.drawings.drill_drawing import draw
    from .studies.hole.drill import drill_hole
    from .studies.hole.hole_run import HoleResult
    from .studies.inputs.shipped import ShippedFile, shipped_files
    from .studies.pages.reproduction_run import ReproductionResult, reproduce
    from .studies.pages.rotation_note import RotationReport, rotation_report
    from .studies.runtime.budgets import Budget, BudgetError
    from .studies.runtime.run_options import RunOptions
    from .studies.scan.study import Study
    from .studies.sensitivity.sensitivity_run import SensitivityResult, sensitivity


def __getattr__(name: str) -> _Any:
    if name in _LAZY:
        import importlib

        module, attribute = _LAZY[name]
        value = getattr(importlib.import_module(f".{module}", __name__), attribute)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'rpdrill' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The public names only (``__all__``)."""
    return sorted(__all__)


__all__ = [
    "AccuracyResult",
    "Advice",
    "AdviceSearch",
    "Budget",
    "BudgetError",
    "CalibrationResult",
    "Crosscheck",
    "EnergyAccount",
    "ExudynMessage",
    "ExudynModel",
    "HoleResult",
    "InputError",
    "Regime",
    "ReproductionResult",
    "Result",
    "RockLaw",
    "RotationReport",
    "RunOptions",
    "Scene",
    "SensitivityResult",
    "ShippedFile",
    "SimulationFailed",
    "StepLimitWarning",
    "Study",
    "UnsettledWarning",
    "WaveStepRounded",
    "accuracy",
    "advise",
    "build_exudyn",
    "calibrate",
    "crosscheck",
    "draw",
    "drill_hole",
    "extension",
    "load_scene",
    "load_study",
    "reproduce",
    "rotation_report",
    "run_study",
    "save_result",
    "sensitivity",
    "shipped_files",
    "simulate",
    "table_frame",
    "view_solution",
    "write_animation",
]
