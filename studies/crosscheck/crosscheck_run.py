"""A cross-check as a library call: :func:`crosscheck` runs one scene in the Exudyn formulation and as
the plain ODE of the paper's Eq. 4 over its first blows (studies.crosscheck.crosscheck_windows) and
returns both runs with their comparison; ``rpdrill crosscheck`` is this function and a print."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...models.definition.formulations import ODE_METHODS
from ...models.definition.scene import Scene
from ...models.evaluation.compare import compare_runs, verdict
from ...models.evaluation.run_result import Result
from ...models.runs.scene_run import run
from ..inputs.arguments import check, choice_problem, count_problem, instance_problem, positive_problem
from ..inputs.reading import prepare_scene, scene_and_source
from ..runtime.budgets import DEFAULT_BUDGET, Budget
from .crosscheck_windows import DEFAULT_STEP_S, comparison_table, window_scenes


@dataclass(frozen=True)
class Crosscheck:
    """The two runs of one window and their differences: ``report`` (models.evaluation.compare:
    histories, the bottom at the window's end, every metric), ``checks`` (each checked figure with its
    tolerance and verdict)."""

    exudyn: Result
    ode: Result
    blows: int
    step_s: float
    report: dict[str, Any]
    checks: dict[str, dict[str, Any]]

    @property
    def passed(self) -> bool:
        """True when every checked figure is within its tolerance."""
        return all(check["passed"] for check in self.checks.values())

    def table(self) -> str:
        """The comparison as the command prints it."""
        return comparison_table(self.report, self.checks)


def crosscheck(scene: Scene | str | Path, blows: int = 20, step_s: float = DEFAULT_STEP_S, method: str = "DOP853",
               rtol: float = 1e-10, budget: Budget | None = DEFAULT_BUDGET,
               allow_code: Sequence[str] | str = ()) -> Crosscheck:
    """The Exudyn model (the scene's solver type at ``step_s``) against the ODE (``method`` at relative
    tolerance ``rtol``) over the first ``blows`` impact periods. InputError or BudgetError before
    anything runs; SimulationFailed when a run diverges. ``allow_code``: the modules of one's own the scene may
    run (models.definition.own_code)."""
    where = "rpdrill.crosscheck"
    check(where, "blows", blows, count_problem)
    check(where, "step_s", step_s, positive_problem)
    check(where, "method", method, choice_problem(ODE_METHODS, "method"))
    check(where, "rtol", rtol, positive_problem)
    check(where, "budget", budget, instance_problem(Budget, "a rpdrill Budget or None", optional=True))
    scene, source = scene_and_source(scene, where, allow_code)  # (allow_code checked there)
    windows = window_scenes(scene, blows, step_s, method, rtol, source)
    simulations = [prepare_scene(window, source) for window in windows]
    if budget is not None:
        for simulation in simulations:
            budget.check_run(simulation, source, f"{simulation.settings.formulation} window: ")
    exudyn, ode = (run(simulation, source=source) for simulation in simulations)
    report = compare_runs(ode.raw, exudyn.raw, windows[0].solver.end_time_s)
    return Crosscheck(exudyn, ode, blows, step_s, report, verdict(report))
