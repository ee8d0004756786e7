"""Calibration: fit scene parameters within bounds so that scans put their optima where wanted.

A calibration file names a base scene (as a study does), the ``parameters`` to fit (dotted scene
path -> [lower, upper]), the frequency axis scanned for every target, the ``metric`` whose
maximum is the optimum, and the ``targets``: scene overrides (e.g. an impulse or a rock) with
the optimum frequency the paper reports. Each evaluation runs every target's scan on the
runner; the optimum of a scan is the vertex of the parabola through the best point and its
neighbours. The objective is sum(((f_opt - f_target) / f_target)^2), a scan with no positive
metric counting as a relative miss of 1. SciPy's bounded Nelder-Mead (or differential
evolution) minimises it over the parameters scaled to [0, 1].
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator
from scipy import optimize

from rpdrill.models.outputs import METRICS
from rpdrill.studies.loading import InputError, parse, read_yaml
from rpdrill.studies.runners import Runner
from rpdrill.studies.study import (
    Axis,
    StrictSpec,
    base_scene_dict,
    check_scene_path,
    prepare_point,
    run_point,
    set_path,
)

FREQUENCY = "impact.frequency_hz"


class Target(StrictSpec):
    """One scan: overrides on the base scene, where its optimum should be [Hz], and the metric
    whose maximum is that optimum (default: the calibration's ``metric``)."""

    overrides: dict[str, Any] = Field(default_factory=dict)
    optimum_hz: float = Field(gt=0)
    metric: str | None = None


class CalibrationSpec(StrictSpec):
    name: str
    base_scene: str | dict[str, Any]
    base_overrides: dict[str, Any] = Field(default_factory=dict)
    parameters: dict[str, tuple[float, float]] = Field(min_length=1)
    frequency_hz: Axis
    metric: str = "penetration_rate_m_per_s"
    targets: list[Target] = Field(min_length=1)
    method: Literal["nelder-mead", "differential-evolution"] = "nelder-mead"
    max_evaluations: int = Field(40, ge=1)

    @model_validator(mode="after")
    def _bounds(self) -> CalibrationSpec:
        for path, (lower, upper) in self.parameters.items():
            if not lower < upper:
                raise ValueError(f"parameters.{path}: lower bound {lower} must be below upper bound {upper}")
        return self


@dataclass
class Calibration:
    source: Path
    spec: CalibrationSpec
    base: dict[str, Any]
    frequencies: list[float]
    history: list[dict[str, Any]] = field(default_factory=list)

    def scene(self, values: dict[str, float], target: Target | None = None, frequency: float | None = None) -> dict:
        """The base scene with parameter values, a target's overrides and a frequency set."""
        scene = copy.deepcopy(self.base)
        for path, value in {**values, **(target.overrides if target else {})}.items():
            set_path(scene, path, value)
        if frequency is not None:
            set_path(scene, FREQUENCY, frequency)
        return scene


def load_calibration(path: str | Path) -> Calibration:
    path = Path(path)
    spec = parse(CalibrationSpec, read_yaml(path), str(path))
    for key, metric in [("metric", spec.metric)] + [(f"targets.{i}.metric", t.metric) for i, t in
                                                     enumerate(spec.targets) if t.metric]:
        if metric not in METRICS:
            raise InputError(f"{path}: {key}: {metric!r}: not a metric; allowed: {', '.join(METRICS)}")
    base = base_scene_dict(spec, path)
    for key in spec.parameters:
        check_scene_path(str(path), "parameters", key, base)
    for i, target in enumerate(spec.targets):
        for key in target.overrides:
            check_scene_path(str(path), f"targets.{i}.overrides", key, base)
    return Calibration(path, spec, base, spec.frequency_hz.expand())


def optimum_hz(frequencies: list[float], values: list[float]) -> float | None:
    """Vertex of the parabola through the maximum and its neighbours (the maximum itself at an end
    of the scan or where the three points are not concave); None when nothing is positive."""
    y = np.asarray(values, dtype=float)
    if not np.any(y > 0):
        return None
    best = int(np.nanargmax(y))
    if best in (0, len(y) - 1):
        return float(frequencies[best])
    (f0, f1, f2), (y0, y1, y2) = frequencies[best - 1:best + 2], y[best - 1:best + 2]
    numerator = (f1 - f0) ** 2 * (y1 - y2) - (f1 - f2) ** 2 * (y1 - y0)
    denominator = (f1 - f0) * (y1 - y2) - (f1 - f2) * (y1 - y0)
    if denominator <= 0:
        return float(f1)
    return float(np.clip(f1 - 0.5 * numerator / denominator, f0, f2))


def evaluate(calibration: Calibration, values: dict[str, float], runner: Runner) -> dict[str, Any]:
    """Run every target's scan at these parameter values: optima and objective."""
    spec = calibration.spec
    metrics = [target.metric or spec.metric for target in spec.targets]
    tasks = [((t, i), prepare_point(str(calibration.source), {**calibration.scene(values, target, f),
                                                               "outputs": {"metrics": [metrics[t]]}}, values))
             for t, target in enumerate(spec.targets) for i, f in enumerate(calibration.frequencies)]
    metric = {}
    for outcome in runner(run_point, tasks):
        (t, _) = outcome["point"]
        metric[outcome["point"]] = outcome["metrics"].get(metrics[t], float("nan"))
    optima, objective = [], 0.0
    for t, target in enumerate(spec.targets):
        found = optimum_hz(calibration.frequencies, [metric[(t, i)] for i in range(len(calibration.frequencies))])
        optima.append(found)
        miss = 1.0 if found is None else (found - target.optimum_hz) / target.optimum_hz
        objective += miss**2
    return {"parameters": values, "optima_hz": optima, "objective": objective}


def calibrate(calibration: Calibration, runner: Runner,
              progress: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """Minimise the objective; returns the best evaluation (all are in ``calibration.history``)."""
    spec = calibration.spec
    names = list(spec.parameters)
    lower = np.array([spec.parameters[n][0] for n in names])
    span = np.array([spec.parameters[n][1] for n in names]) - lower

    def objective(unit: np.ndarray) -> float:
        values = {n: float(v) for n, v in zip(names, lower + span * np.clip(unit, 0, 1), strict=True)}
        record = evaluate(calibration, values, runner)
        calibration.history.append(record)
        if progress:
            progress(record)
        return record["objective"]

    base_values = [_get(calibration.base, n) for n in names]
    start = np.clip([(v - lo) / s if isinstance(v, (int, float)) else 0.5
                     for v, lo, s in zip(base_values, lower, span, strict=True)], 0, 1)
    bounds = [(0.0, 1.0)] * len(names)
    if spec.method == "nelder-mead":
        optimize.minimize(objective, start, method="Nelder-Mead", bounds=bounds,
                          options={"maxfev": spec.max_evaluations, "xatol": 1e-3, "fatol": 1e-6,
                                   "initial_simplex": _simplex(start)})
    else:
        population = max(2, math.ceil(spec.max_evaluations / (len(names) * 5)) - 1)
        optimize.differential_evolution(objective, bounds, maxiter=population, popsize=5, x0=start,
                                        polish=False, seed=1, tol=1e-6)
    return min(calibration.history, key=lambda r: r["objective"])


def _simplex(start: np.ndarray) -> np.ndarray:
    """A simplex of steps of 0.25 (a quarter of each bound's width) around the start."""
    points = [start]
    for i in range(len(start)):
        point = start.copy()
        point[i] = point[i] + 0.25 if point[i] <= 0.75 else point[i] - 0.25
        points.append(point)
    return np.array(points)


def _get(data: dict[str, Any], path: str) -> Any:
    for key in path.split("."):
        data = data.get(key, {}) if isinstance(data, dict) else {}
    return data
