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
    """The two runs of one window of :func:`crosscheck` and their differences.

    Parameters
    ----------
    exudyn, ode : Result
        The Exudyn model's run and the ODE's.
    blows : int
        The window in impact periods.
    step_s : float
        Exudyn's step.
    report : dict
        Every difference (models.evaluation.compare): the histories, the bottom at the window's end, every metric.
    checks : dict of str to dict
        Each checked figure with its tolerance and verdict (``passed``).

    Attributes
    ----------
    passed : bool
        True when every checked figure is within its tolerance.

    Examples
    --------
    >>> import rpdrill
    >>> check = rpdrill.crosscheck("paper_base", blows=15)  # doctest: +SKIP
    >>> check.passed, check.exudyn.formulation, check.ode.formulation  # doctest: +SKIP
    (True, 'exudyn', 'ode')
    """

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
    """The Exudyn model against the paper's Eq. 4 as a plain ODE over the first blows (``rpdrill crosscheck``).

    Both run the same window from the scene's start: Exudyn with the scene's solver type at ``step_s``, SciPy's
    ``method`` at relative tolerance ``rtol``; their histories, the bottom at the window's end and every metric
    are compared, each checked figure against its tolerance (docs/crosscheck.md).

    Parameters
    ----------
    scene : Scene, str or pathlib.Path
        The scene, a scene file or a shipped scene's name.
    blows : int, default 20
        The window: this many impact periods (at least the metrics' transient and block blows).
    step_s : float, default 5e-6
        Exudyn's step.
    method : {"DOP853", "Radau", "LSODA"}, default "DOP853"
        The ODE's integrator.
    rtol : float, default 1e-10
        The ODE's relative tolerance.
    budget : Budget or None, default Budget()
        The steps and memory each run may take (None: unchecked).
    allow_code : sequence of str or str, default ()
        The modules of one's own the scene may run (models.definition.own_code).

    Returns
    -------
    Crosscheck
        The two runs, the report of their differences, each check and ``passed``.

    Raises
    ------
    InputError
        When an input cannot be used, before anything runs.
    BudgetError
        When a run exceeds ``budget``, before anything runs.
    SimulationFailed
        When a run diverges.

    Examples
    --------
    >>> import rpdrill
    >>> check = rpdrill.crosscheck("paper_base", blows=15)  # doctest: +SKIP
    >>> check.passed, list(check.checks)  # doctest: +SKIP
    (True, ['bottom_at_window_end_rel', 'bit_velocity_rel_to_range'])
    >>> print(check.table())  # doctest: +SKIP
    """
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
