"""One point of an analysis: a typed scene made from a base scene and axis values, prepared, run.

A point's scene is ``base.with_(values)`` (models.definition.scene.Scene.with_: validated, so that any
scene key path the scene accepts is an axis), its problems tied to the axis that caused them when
there is one (:func:`point_scene`). It is prepared once where it is made (models.solvers.simulation.prepare:
the chain, the rock law, the solver settings, the initial state; studies.inputs.reading.prepare_scene);
a worker receives the prepared simulation and builds the formulation's model itself (Exudyn systems
cannot be pickled). :func:`run_point` runs it as its scene asks (models.runs.scene_run.run: a time
run, or its steady state) into one row of a results table: the columns :func:`point_columns` names, what
the run returns (its status, the steady state's columns, the metrics). Points along an axis run in order
(a curve, a continuation study's chain: :func:`run_followed`) start each periodic orbit's Newton from
their neighbours' (models.steady.continuation).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

from ...models.definition.scene import Scene
from ...models.definition.validation import short
from ...models.evaluation.run_record import SteadyStateRecord
from ...models.evaluation.run_result import Result
from ...models.evaluation.run_status import STATUSES, run_status
from ...models.runs.scene_run import OrbitGuess, run
from ...models.solvers.simulation import Simulation
from ...models.steady.continuation import Continuation, branch_point
from ..inputs.reading import InputError, prepare_scene

# what a run returns besides its metrics, in the order of a results table's columns (the steady state's:
# models.evaluation.run_record.SteadyStateRecord.columns)
STATUS_COLUMNS = ("status", "error", "steady_state", "regime", "wall_time_s", "period_blows", "floquet_max_abs")
# a finished point's status: ok; failed (its error says why); unstable, unsettled, not_finite or
# unbalanced (metrics written, but the run's figures do not stand as they are: models.evaluation.run_status)
FINISHED = ("failed", *STATUSES)


def _point_errors(source: str, problems: Sequence[tuple[str, str]], values: Mapping[str, Any]) -> list[str]:
    """Problems of one point, each tied to the axis that caused it when there is one."""
    lines = []
    for location, message in problems:
        related = [a for a in values if a == location or a.startswith(location + ".") or location.startswith(a + ".")]
        parent = location.rpartition(".")[0]
        if not related and parent:  # a check across keys (a pulse longer than the period): its sibling axes
            related = [a for a in values if a.startswith(parent + ".")]
        if len(related) == 1:
            lines.append(f"{source}: scan.{related[0]}: {short(values[related[0]])}: {message}")
        else:
            lines.append(f"{source}: {where(values)}{location or 'scene'}: {message}")
    return lines


def where(values: Mapping[str, Any]) -> str:
    """'scan point {...}: ' naming a point by its axis values in a message ('' without any)."""
    return f"scan point {dict(values)}: " if values else ""


def point_scene(base: Scene, values: Mapping[str, Any], source: str, fixed: Mapping[str, Any] | None = None) -> Scene:
    """The point's scene: ``base.with_`` the ``fixed`` changes every point shares (its outputs, a
    calibration's parameters), then its axis ``values`` (key path -> value); InputError naming ``source``
    and the axis that made it invalid (or the point)."""
    try:
        return base.with_({**(fixed or {}), **values}, source)
    except InputError as error:
        if not error.problems or not values:
            raise
        raise InputError("\n".join(_point_errors(source, error.problems, values))) from None


def prepare_point(base: Scene, values: Mapping[str, Any], source: str,
                  fixed: Mapping[str, Any] | None = None) -> Simulation:
    """:func:`point_scene`, prepared; InputError also when its formulation cannot run it."""
    return prepare_scene(point_scene(base, values, source, fixed), source, where(values))


def point_columns(metrics: Sequence[str]) -> list[str]:
    """The columns of a point's row (:func:`run_point`) when ``metrics`` are asked for."""
    return [*STATUS_COLUMNS, *metrics]


def run_prepared(simulation: Simulation, guess: OrbitGuess | None = None, cold_newton: bool = True,
                 start_check: bool = True) -> tuple[dict[str, Any], Result | None]:
    """Run one prepared point as its scene asks (models.runs.scene_run.run: a time run, or its
    steady state from ``guess``, a neighbour's orbit; ``cold_newton``: as there) into its row
    (:func:`point_columns`): status (models.evaluation.run_status: ok, unstable, unsettled, not_finite or
    unbalanced, the reason in ``error``; a steady state's note where the run is ok; ``start_check``: as
    models.runs.scene_run.run's), the steady state's
    columns, wall time and every metric of its outputs; a failure is returned (status ``failed``, the
    exception in ``error``, no metrics), not raised. The row and the run (None if it failed)."""
    start = time.perf_counter()
    try:
        result = run(simulation, guess=guess, cold_newton=cold_newton, start_check=start_check)
        metrics = result.metrics
        status, why = run_status(result.raw, metrics)
    except Exception as err:  # noqa: BLE001 - one bad point is recorded and the analysis goes on
        failed = SteadyStateRecord(simulation.scene.solver.steady_state).columns()
        return {"status": "failed", "error": f"{type(err).__name__}: {err}", **failed, "regime": "",
                "wall_time_s": time.perf_counter() - start}, None
    if result.steady_state.note and status == "ok":
        why = result.steady_state.note
    return {"status": status, "error": why, **result.steady_state.columns(),
            "wall_time_s": time.perf_counter() - start, **metrics}, result


def run_point(simulation: Simulation) -> dict[str, Any]:
    """Worker: one prepared point's row (:func:`run_prepared`)."""
    return run_prepared(simulation)[0]


def run_followed(branch: Continuation, value: float, simulation: Simulation, start_check: bool = True
                 ) -> dict[str, Any]:
    """One point of a sequence along an axis at ``value``, run after the points before it (module doc):
    Newton from ``branch``'s prediction, which then takes this point's orbit (every point's, a failed
    one's too, so that the passes of a chain align: models.steady.continuation). Its row."""
    row, result = run_prepared(simulation, branch.guess(value), branch.cold_newton, start_check)
    branch.add(branch_point(value, None if result is None else result.steady_state,
                            row.get("advance_per_blow_m", math.nan)))
    return row
