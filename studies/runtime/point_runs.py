"""One scene of a study, an accuracy study or a calibration: prepared once, run by a worker.

Every point is validated and prepared where it is made (models.solvers.simulation.prepare: the chain, the
rock law, the solver settings, the initial state); workers receive the prepared simulation and
build the formulation's model themselves (Exudyn systems cannot be pickled). A point's problems
are tied to the scan axis that caused them when there is one.
"""

from __future__ import annotations

import time
from typing import Any

from pydantic import ValidationError

from ...models.definition.scene import Scene
from ...models.definition.validation import problem, short
from ...models.evaluation.metrics import summary_metrics
from ...models.evaluation.results import SimulationResult
from ...models.evaluation.run_status import run_status
from ...models.solvers.simulation import Simulation
from ...models.steady.steady_run import OrbitGuess, regime_columns, run_scene
from ..inputs.reading import InputError, prepare_scene


def _point_error(source: str, error: ValidationError, parameters: dict[str, Any]) -> list[str]:
    """Problems of one point, each tied to the scan axis that caused it when there is one."""
    lines = []
    for item in error.errors():
        loc = ".".join(str(p) for p in item["loc"] if p != "function-after")
        related = [a for a in parameters if a == loc or a.startswith(loc + ".") or loc.startswith(a + ".")]
        parent = loc.rpartition(".")[0]
        if not related and parent:  # a check across keys (a pulse longer than the period): its sibling axes
            related = [a for a in parameters if a.startswith(parent + ".")]
        message = problem(item)
        if len(related) == 1:
            lines.append(f"{source}: scan.{related[0]}: {short(parameters[related[0]])}: {message}")
        else:
            lines.append(f"{source}: {_point(parameters)}{loc or 'scene'}: {message}")
    return lines


def _point(parameters: dict[str, Any]) -> str:
    return f"scan point {parameters}: " if parameters else ""


def prepare_point(source: str, scene: dict[str, Any], parameters: dict[str, Any]) -> Simulation:
    """Validate and prepare one point's scene; InputError naming the scan axis that made it invalid
    (or the point), and when its formulation cannot run it (studies.inputs.reading.prepare_scene)."""
    try:
        validated = Scene.model_validate(scene)
    except ValidationError as error:
        raise InputError("\n".join(_point_error(source, error, parameters))) from None
    return prepare_scene(validated, source, _point(parameters))


def run_prepared(key: Any, simulation: Simulation, guess: OrbitGuess | None = None, cold_newton: bool = True
                 ) -> tuple[dict[str, Any], SimulationResult | None]:
    """Run one prepared point as its scene asks (models.steady.steady_run.run_scene: a time run, or its
    steady state from ``guess``, a neighbour's orbit) and collect its outputs' metrics, its status
    (models.evaluation.run_status: ok, unstable, unsettled, not_finite or unbalanced, the reason in
    ``error``) and its steady-state
    columns (regime, period_blows, floquet_max_abs); a failure is returned, not raised. The outcome and
    the run (None if it failed). ``cold_newton``: models.steady.steady_run.run_scene."""
    start = time.perf_counter()
    try:
        result = run_scene(simulation, guess, cold_newton=cold_newton)
        metrics = summary_metrics(result)
        status, why = run_status(result, metrics)
    except Exception as err:  # noqa: BLE001 - one bad point is recorded and the study goes on
        return {"point": key, "status": "failed", "error": f"{type(err).__name__}: {err}",
                "wall_time_s": time.perf_counter() - start, "metrics": {}, **regime_columns(None),
                "steady_state": simulation.scene.solver.steady_state}, None
    if result.info.get("steady_state_note") and status == "ok":
        why = result.info["steady_state_note"]
    return {"point": key, "status": status, "error": why, "wall_time_s": time.perf_counter() - start,
            "metrics": metrics, **regime_columns(result)}, result


def run_point(task: tuple[Any, Simulation]) -> dict[str, Any]:
    """Worker: run one prepared point ``(key, simulation)`` (:func:`run_prepared`)."""
    return run_prepared(*task)[0]
