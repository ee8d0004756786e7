"""The bifurcation diagram of a drill along one scene key: what every blow of the settled response does,
by time runs (brute force) and by the orbits followed along the axis.

For each value of the axis (:func:`bifurcation_data`):

* brute force: an exact time run from the scene's start of ``settle_blows`` blows; the advance and the peak
  rock force of each of its last ``last_blows`` blows (a period-n response shows n values, an irregular one
  a cloud);
* the attractors followed from both ends of the axis (models.steady.continuation through
  models.runs.scene_run.run: the stable orbits, their advance and peak rock force per blow of the
  orbit, and the regime);
* the period-1 orbit followed up the axis from the first stable one whatever its stability, until Newton
  loses it (its unstable stretches are the orbits a drill never shows).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ...models.definition.scene import Scene
from ...models.evaluation.results import SimulationResult
from ...models.runs.scene_run import run
from ...models.solvers.exact_model import BLAS
from ...models.solvers.simulation import prepare
from ...models.steady.continuation import BranchPoint, Continuation, branch_point
from ...models.steady.exact_map import exact_period_map
from ...models.steady.shooting import NoConvergence, Shooter


@dataclass(frozen=True)
class BlowFigures:
    """The advance [m] and peak rock force [N] of each blow of a response at one axis value."""

    value: float
    advance_m: tuple[float, ...]
    peak_rock_force_n: tuple[float, ...]
    regime: str = ""
    stable: bool = True
    state: tuple[float, ...] | None = None  # an orbit's section state (models.steady.section)


@dataclass
class Diagram:
    """The diagram's data along ``axis`` (module doc)."""

    axis: str
    brute_force: list[BlowFigures] = field(default_factory=list)
    up: list[BlowFigures] = field(default_factory=list)
    down: list[BlowFigures] = field(default_factory=list)
    period_one: list[BlowFigures] = field(default_factory=list)


def blow_figures(result: SimulationResult, blows: int, value: float, regime: str = "",
                 stable: bool = True) -> BlowFigures:
    """The last ``blows`` whole blows of a run: each one's advance and peak rock force."""
    period = result.scene.impact.period_s
    last = math.floor(result.time_s[-1] / period + 1e-9)
    starts = np.arange(last - blows, last + 1) * period
    advances = np.diff(result.bottom_at(starts))
    peaks = [float(np.max(result.rock_force_n[(result.time_s >= a - 1e-12) & (result.time_s <= b + 1e-12)]))
             for a, b in itertools.pairwise(starts)]
    return BlowFigures(value, tuple(float(a) for a in advances), tuple(peaks), regime, stable)


def _scene(base: Scene, axis: str, value: float, **solver: Any) -> Scene:
    """``base`` at ``value``, its end time at least its metrics' blows (the periodic runs' fallback)."""
    frequency_hz = float(value) if axis == "impact.frequency_hz" else base.impact.frequency_hz
    needed = (base.metrics.transient_blows + base.metrics.block_blows) / frequency_hz
    solver = {"end_time_s": max(base.solver.end_time_s, needed), **solver}
    return base.with_({axis: value, "outputs": {"metrics": ["penetration_rate_m_per_s"], "timeseries": ["rock_force_n"]},
                       **{f"solver.{k}": v for k, v in solver.items()}})


def _followed(base: Scene, axis: str, values: Sequence[float]) -> list[BlowFigures]:
    """The attractors along ``values`` in their order (module doc)."""
    branch, figures = Continuation(), []
    for value in values:
        result = run(prepare(_scene(base, axis, value, steady_state="periodic")), guess=branch.guess(value),
                     cold_newton=branch.cold_newton)
        steady = result.steady_state
        branch.add(branch_point(value, steady, math.nan))
        blows = steady.period_blows or result.scene.metrics.block_blows
        figures.append(replace(blow_figures(result.raw, blows, value, steady.regime_name),
                               state=None if steady.orbit is None else tuple(steady.orbit.state)))
    return figures


def _period_one(base: Scene, axis: str, values: Sequence[float], start: BlowFigures | None) -> list[BlowFigures]:
    """The period-1 orbit from the first stable one up the axis (``start``) whatever its stability, until
    Newton loses it (module doc)."""
    if start is None:
        return []
    branch, figures = Continuation(), []
    for value in [v for v in values if v >= start.value]:
        simulation = prepare(_scene(base, axis, value, steady_state="periodic"))
        period_map = exact_period_map(simulation)
        guess = branch.guess(value) or (np.array(start.state), 1)
        try:
            with BLAS.limit(limits=1, user_api="blas"):
                orbit = Shooter(period_map, simulation).solve(guess[0])
        except NoConvergence:
            break
        result, _ = period_map.result(orbit.state, 1, 0.0)
        branch.add(BranchPoint(value, "period-1", 1, math.nan, orbit.state, np.array(orbit.multipliers), ()))
        figures.append(blow_figures(result, 1, value, "period-1", orbit.stable))
    return figures


def bifurcation_data(base: Scene, axis: str, values: Sequence[float], settle_blows: int = 200,
                     last_blows: int = 40) -> Diagram:
    """The diagram of the scene ``base`` (exact formulation) along the scene key ``axis`` (module doc)."""
    base = base.with_solver("exact")
    diagram = Diagram(axis)
    for value in values:
        frequency_hz = float(value) if axis == "impact.frequency_hz" else base.impact.frequency_hz
        scene = _scene(base, axis, value, end_time_s=settle_blows / frequency_hz, steady_state="time")
        diagram.brute_force.append(blow_figures(run(prepare(scene)).raw, last_blows, value))
    diagram.up = _followed(base, axis, values)
    diagram.down = _followed(base, axis, values[::-1])[::-1]
    diagram.period_one = _period_one(base, axis, values, next((f for f in diagram.up if f.regime == "period-1"), None))
    return diagram
