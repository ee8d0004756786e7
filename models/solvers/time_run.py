"""The formulation's run of a prepared scene from its start to its end time: what the one run path
(models.runs.scene_run.run) and the steady-state machinery's runs (models.steady) call."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..definition.extensions import refusal
from ..evaluation.results import SimulationResult
from .simulation import SceneError, Simulation, implementation


def time_run(simulation: Simulation, progress: Callable[[float], None] | None = None,
             solution_file: Path | None = None) -> SimulationResult:
    """The formulation's run of ``simulation`` from its start to its end time (models.solvers.simulation.implementation);
    ``progress(t)`` as simulated time advances. The steady-state machinery's runs (models.steady) and the one
    run path (models.runs.scene_run.run, which honours ``solver.steady_state``) call it; nothing else does.
    ``solution_file``: with the Exudyn formulation, Exudyn's coordinates solution file written there during
    the run (every output interval; for its SolutionViewer); the other formulations write none. SceneError
    naming the extension when the formulation builds no Exudyn model and the scene has an extension that
    changes the motion (models.definition.extensions)."""
    refused = refusal(simulation.scene.extensions, simulation.settings.formulation)
    if refused:
        raise SceneError(("extensions", refused[0]), simulation.scene.extensions[refused[0]].function, refused[1])
    if solution_file is None or simulation.settings.formulation != "exudyn":
        return implementation(simulation.settings.formulation).simulate(simulation, progress)
    from .exudyn_model import build_exudyn  # Exudyn loaded only for its own solution file

    model = build_exudyn(simulation)
    model.write_solution(solution_file)
    result = model.run_raw(progress)
    result.solution_file = Path(solution_file)
    return result
