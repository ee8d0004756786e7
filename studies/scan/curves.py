"""Scans along one axis of a base scene, each run in order by one worker, and their optima: what the
calibration fits, the sensitivity study varies, the reproduction reports and advice searches.

A :class:`Curve` is the points of a base scene with some changes along one scene key path (by default
the impact frequency), made as every analysis makes its points (studies.runtime.point_runs.point_scene:
``base.with_({**changes, axis: value})``, each point validated on its own: a change may be valid at
some values of the axis only) and asking for ``metrics`` only. :func:`run_curve` runs them in order in
one worker, each into the row a study's results table holds (studies.runtime.point_runs.run_followed: a
periodic run starts from the orbits of the points before it), and
returns a :class:`CurveRun`: that table, the scene's rock-mode frequency (models.drill.modal: along the
frequency, the main lobe is the one nearest to it) and the CPU seconds; its optimum of a metric is the
studies.scan.curve_optima.Optimum a study's curve has. Many curves (every scan of many parameter sets)
go to a runner together, one task per curve, each distinct curve once; ``rising`` lists of labels are
trends the optima must follow (the paper's 3.1 b: the optimum rises with the impulse).
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import Field

from ...models.definition.scene import Scene
from ...models.drill.modal import rock_mode_frequency_hz
from ...models.steady.continuation import Continuation
from ..inputs.reading import InputError
from ..inputs.specs import MetricName, StrictSpec
from ..runtime.point_runs import point_columns, prepare_point, run_followed
from ..runtime.pools import Runner
from .curve_optima import FREQUENCY, Optimum, curve_optimum

if TYPE_CHECKING:
    import pandas as pd


class Scan(StrictSpec):
    """One frequency scan of the base scene with ``overrides``; its optimum is that of ``metric``
    (default: the file's ``metric``)."""

    label: str | None = None
    overrides: dict[str, Any] = Field(default_factory=dict)
    metric: MetricName | None = None


@dataclass(frozen=True)
class Curve:
    """The points ``base.with_({**changes, axis: value})`` for each of ``values`` (scene key path ->
    value), asking for ``metrics`` only (the model then records only what they need); ``key`` names it
    among the curves of one call."""

    key: Any
    base: Scene
    changes: dict[str, Any]
    values: tuple[float, ...]
    metrics: tuple[str, ...]
    axis: str = FREQUENCY

    @property
    def signature(self) -> str:
        """What determines its results: equal signatures, equal runs."""
        return json.dumps([self.base.model_dump(mode="json", by_alias=True), self.changes, self.axis,
                           list(self.values), list(self.metrics)], sort_keys=True)


@dataclass(frozen=True)
class CurveRun:
    """A curve run: its ``table`` (one row a point: the axis value, then the row of
    studies.runtime.point_runs.run_point), the rock-mode frequency of its scene (None if it has none,
    or along another axis than the frequency) and the CPU seconds of its runs."""

    key: Any
    axis: str
    table: pd.DataFrame
    resonance_hz: float | None
    cpu_time_s: float

    @property
    def failed_runs(self) -> int:
        return int((self.table["status"] == "failed").sum())

    @property
    def error(self) -> str:
        """The first failed point's error ('' when none failed)."""
        errors = self.table.loc[self.table["status"] == "failed", "error"]
        return str(errors.iloc[0]) if len(errors) else ""

    def values(self, metric: str) -> list[float]:
        """A metric at every point (NaN where the run failed; an unsettled or unstable run has its value)."""
        failed = (self.table["status"] == "failed").to_numpy()
        return list(np.where(failed, math.nan, self.table[metric].to_numpy(dtype=float, na_value=math.nan)))

    def optimum(self, metric: str) -> Optimum:
        """The optimum of ``metric`` along the curve (studies.scan.curve_optima)."""
        return curve_optimum(self.table[self.axis].to_numpy(dtype=float), self.values(metric), self.resonance_hz,
                             metric=metric, along=self.axis, failed=self.failed_runs)


def run_order(curve: Curve) -> list[int]:
    """The order its points run in (indices of ``curve.values``): along the frequency from the highest down
    (a periodic run starts Newton from its neighbours' orbits, models.steady.continuation; the orbits of the
    fastest blows have the fewest switches and the irregular bouncing of a poorly tuned drill lies at the
    slow end, so the branch is followed from where it is surest), along another axis as given."""
    indices = range(len(curve.values))
    return sorted(indices, key=lambda i: -curve.values[i]) if curve.axis == FREQUENCY else list(indices)


def run_curve(curve: Curve) -> CurveRun:
    """Worker: every point of the curve (in :func:`run_order`, the table in the curve's order; a point that
    does not validate or prepare is a failed row, its message the error; failures are recorded, not raised),
    the rock-mode frequency of the first point that prepares (along the frequency) and the CPU seconds."""
    import pandas as pd

    start = time.process_time()
    rows, resonance = {}, None
    branch = Continuation()  # solver.steady_state periodic: each orbit from its neighbours' (models.steady)
    for index in run_order(curve):
        value = curve.values[index]
        try:
            simulation = prepare_point(curve.base, {curve.axis: value}, f"{curve.axis} scan",
                                       {**curve.changes, "outputs": {"metrics": list(curve.metrics)}})
        except InputError as error:
            rows[index] = {curve.axis: value, "status": "failed", "error": str(error), "wall_time_s": 0.0}
            continue
        if curve.axis == FREQUENCY:
            resonance = resonance or rock_mode_frequency_hz(simulation.chain, simulation.rock) or None
        # (a curve is read for its optima: where each orbit's start goes is a study's and a run's to say)
        rows[index] = {curve.axis: value, **run_followed(branch, value, simulation, start_check=False)}
    table = pd.DataFrame([rows[i] for i in sorted(rows)], columns=[curve.axis, *point_columns(curve.metrics)])
    return CurveRun(curve.key, curve.axis, table, resonance, time.process_time() - start)


def run_curves(runner: Runner, curves: Sequence[Curve]) -> Iterator[tuple[list[Any], CurveRun]]:
    """Run the curves on the runner, each distinct curve once (two may be the same); yields (the keys of
    the curves it answers, its run) as runs end."""
    keys: dict[str, list[Any]] = {}
    first: dict[str, Curve] = {}
    for curve in curves:
        keys.setdefault(curve.signature, []).append(curve.key)
        first.setdefault(curve.signature, curve)
    served = {curve.key: keys[signature] for signature, curve in first.items()}
    for batch in runner(run_curve, list(first.values())) if first else ():
        for run in batch:
            yield served[run.key], run


def run_all(runner: Runner, curves: Sequence[Curve]) -> tuple[dict[Any, CurveRun], dict[str, Any]]:
    """Every curve's run by its key, and what the distinct runs cost (:func:`runs_cost`)."""
    runs, ran = {}, []
    for served, run in run_curves(runner, curves):
        runs.update(dict.fromkeys(served, run))
        ran.append(run)
    return runs, runs_cost(ran)


def runs_cost(runs: Sequence[CurveRun]) -> dict[str, Any]:
    """Simulations, failed runs and CPU seconds of distinct curve runs."""
    return {"simulations": sum(len(run.table) for run in runs), "failed_runs": sum(run.failed_runs for run in runs),
            "cpu_time_s": sum(run.cpu_time_s for run in runs)}


def rising_shortfalls(rising: list[list[str]], optima: dict[str, float | None]) -> list[tuple[str, str, float]]:
    """(a, b, x_a - x_b) for neighbouring labels of each rising list whose optima do not rise (pairs
    where a scan has no optimum are left out)."""
    return [(a, b, optima[a] - optima[b]) for chain in rising for a, b in itertools.pairwise(chain)
            if optima[a] is not None and optima[b] is not None and optima[a] >= optima[b]]
