"""Resource budgets, checked before anything runs: the steps and memory of every run
(models.solvers.cost), and the CPU time and memory of a command's many runs.

A run or a command beyond its budget stops with exit status 1 and one message: the file, the key
that causes the cost, its value, the estimate and the option that allows it (``--max-steps``,
``--max-memory-gb``, ``--yes``). The limits are stated here:

* DEFAULT_MAX_STEPS steps per run (Exudyn on the paper drill takes about 6 microseconds a step,
  models.solvers.cost: a minute);
* DEFAULT_MAX_MEMORY_GB of memory per run, and for a study's prepared points together
  (PREPARED_POINT_BYTES each);
* MAX_CPU_HOURS of CPU for a command's runs together (their preparation included), unless
  ``--yes``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ...models.definition.scene import Scene
from ...models.solvers.cost import Cause, RunCost, run_cost
from ...models.solvers.simulation import Simulation
from ..inputs.reading import InputError
from .point_runs import prepare_point

DEFAULT_MAX_STEPS = 1e7
DEFAULT_MAX_MEMORY_GB = 2.0
MAX_CPU_HOURS = 1.0
# What a command holds besides its runs, rounded up from benchmarks/bench_budgets.py: a prepared study
# point (14 kB on paper_base, 24 kB on the four-rod string) and the CPU time to prepare it (0.8-0.9
# ms), a calibration's evaluation record (6 kB for the shipped calibration), a value of a
# calibration's frequency axis (a float in a list).
PREPARED_POINT_BYTES = 30e3
PREPARE_S_PER_POINT = 1e-3
EVALUATION_BYTES = 10e3
AXIS_VALUE_BYTES = 32


class BudgetError(Exception):
    """A run or a call beyond its :class:`Budget`, refused before it starts (exit status 1 on the command line).

    The message is complete: the source, the key that causes the cost, its value, the estimate and the option
    that allows it.

    Parameters
    ----------
    *args
        The message, as for any exception.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 100.0})
    >>> try:
    ...     rpdrill.simulate(scene, budget=rpdrill.Budget(max_steps=1e5))
    ... except rpdrill.BudgetError as error:
    ...     print(error.__class__.__name__)
    BudgetError
    """


def duration(seconds: float) -> str:
    """A CPU time for a message: seconds, minutes or hours."""
    if seconds < 120:
        return f"{seconds:.3g} s"
    return f"{seconds / 60:.3g} min" if seconds < 7200 else f"{seconds / 3600:.3g} h"


@dataclass(frozen=True)
class Budget:
    """The limits a call checks its runs against before they start (module doc; the command line's ``--max-steps``,
    ``--max-memory-gb``, ``--yes``).

    Parameters
    ----------
    max_steps : float, default 1e7
        The steps one run may take.
    max_memory_gb : float, default 2.0
        The memory one run may hold, and a study's prepared points together, in GB.
    accept_long : bool, default False
        Allow more than 1 h of CPU for a call's runs together.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 100.0, "solver.step_s": 1e-7})
    >>> try:
    ...     rpdrill.simulate(scene, budget=rpdrill.Budget(max_steps=1e8))
    ... except rpdrill.BudgetError as error:
    ...     print(error)
    scene 'paper_base': solver.step_s: 1e-07: the run would take 1e+09 steps of 1e-07 s over solver.end_time_s 100
    (about ... of CPU); at most 1e+08 steps per run (--max-steps)
    """

    max_steps: float = DEFAULT_MAX_STEPS
    max_memory_gb: float = DEFAULT_MAX_MEMORY_GB
    accept_long: bool = False

    def check_run(self, simulation: Simulation, source: str, where: str = "", resampled: Cause | None = None) -> RunCost:
        """The run's cost (models.solvers.cost, histories resampled at the interval ``resampled`` names);
        BudgetError naming ``source``, ``where`` (a scan point, a setting), the key and value that cause
        it when it is beyond the steps or memory budget."""
        cost = run_cost(simulation, resampled)
        end = simulation.settings.end_time_s
        if cost.steps > self.max_steps:
            cause = cost.steps_cause
            raise BudgetError(
                f"{source}: {where}{cause.key}: {_value(cause.value)}: the run would take {cost.steps:.3g} steps of "
                f"{cost.step_s:.3g} s over solver.end_time_s {end:g} (about {duration(cost.cpu_s)} of CPU); "
                f"at most {self.max_steps:.3g} steps per run (--max-steps)")
        if cost.memory_bytes > self.max_memory_gb * 1e9:
            cause = cost.memory_cause
            raise BudgetError(
                f"{source}: {where}{cause.key}: {_value(cause.value)}: the run would hold about "
                f"{cost.memory_bytes / 1e9:.3g} GB (solver.end_time_s {end:g}); at most {self.max_memory_gb:g} GB "
                "per run (--max-memory-gb)")
        return cost

    def check_total(self, source: str, what: str, runs: float, cpu_s: float, memory_bytes: float = 0.0) -> None:
        """BudgetError when ``runs`` runs of ``cpu_s`` CPU seconds together (``what`` says where they
        come from), or what the command holds for them (``memory_bytes``), are beyond the budget."""
        if cpu_s > MAX_CPU_HOURS * 3600 and not self.accept_long:
            raise BudgetError(f"{source}: {what}: {runs:.6g} runs, estimated {duration(cpu_s)} of CPU; more than "
                              f"{MAX_CPU_HOURS:g} h needs --yes")
        if memory_bytes > self.max_memory_gb * 1e9:
            raise BudgetError(f"{source}: {what}: {runs:.6g} runs; holding them takes about "
                              f"{memory_bytes / 1e9:.3g} GB; at most {self.max_memory_gb:g} GB (--max-memory-gb)")


DEFAULT_BUDGET = Budget()


def base_estimate_s(source: str, base: Scene, changes: Mapping[str, Any] | None = None) -> float:
    """Estimated CPU seconds of a run of ``base`` with ``changes`` (0 when it does not prepare: its points
    will say why), before the points are expanded: the drill without its extensions (a lower bound; each
    point's estimate sizes the model its extensions make, so that they run once a point here, not more)."""
    plain = {**(changes or {}), "extensions": None} if base.extensions else changes
    try:
        return run_cost(prepare_point(base, {}, source, plain)).cpu_s
    except InputError:
        return 0.0


def check_size(budget: Budget, source: str, what: str, count: float, run_s: float) -> None:
    """Before ``count`` points are expanded and prepared: their preparation and runs (``run_s`` each,
    estimated) against the CPU budget, the prepared points against the memory budget."""
    budget.check_total(source, what, count, count * (PREPARE_S_PER_POINT + run_s), count * PREPARED_POINT_BYTES)


def _value(value: float | str) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)
