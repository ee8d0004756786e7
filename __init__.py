"""rpdrill: multibody simulation of rotary-percussive rock drilling on Exudyn.

The public API (every name documented with an example in ``docs/api.md``)::

    import rpdrill
    scene = rpdrill.load_scene("studies/scenes/paper_base.yaml")
    scene = scene.with_({"impact.frequency_hz": 70.0, "solver.formulation": "exact"})
    result = rpdrill.simulate(scene)
    result.metrics["penetration_rate_m_per_s"]
    table = rpdrill.run_study(rpdrill.load_study("studies/paper/frequency_scan.yaml"), workers=2)

The package's folders: ``rocklaw`` (the rock contact laws), ``models`` (the drill models and their
three formulations), ``studies`` (YAML inputs, scans, analyses, reports and the command line);
dependencies run one way, studies -> models -> rocklaw (``docs/architecture.md``).
"""

from .models.definition.scene import Scene
from .models.definition.validation import InputError
from .models.evaluation.stability import SimulationFailed
from .studies.api import Result, load_scene, load_study, run_study, simulate, table_frame
from .studies.runtime.budgets import BudgetError
from .studies.scan.study import Study

__all__ = ["BudgetError", "InputError", "Result", "Scene", "SimulationFailed", "Study", "load_scene", "load_study",
           "run_study", "simulate", "table_frame"]
