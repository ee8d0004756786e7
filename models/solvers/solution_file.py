"""A run that writes Exudyn's coordinates solution file as it goes (for Exudyn's SolutionViewer,
studies.drawings.drill_animation.view_solution), beside the plain run of every formulation."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..evaluation.results import SimulationResult
from .simulation import Simulation


def solve_with_solution(simulation: Simulation, progress: Callable[[float], None] | None = None,
                        solution: Path | None = None) -> SimulationResult:
    """Run ``simulation`` with its formulation; with ``solution`` and the Exudyn formulation, Exudyn's
    coordinates solution file written there during the run (every output interval). The other
    formulations write none."""
    if solution is None or simulation.settings.formulation != "exudyn":
        return simulation.solve(progress)
    from .exudyn_model import build_exudyn  # Exudyn loaded only for its own solution file

    model = build_exudyn(simulation)
    model.write_solution(solution)
    result = model.solve(progress)
    result.info["solution_file"] = str(solution)
    return result
