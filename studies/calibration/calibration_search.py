"""Calibration: fit scene parameters within bounds so that scans put their main-lobe optima where
the paper does.

An evaluation of a parameter set runs every target's frequency scan (studies.calibration.calibration_spec;
a studies.scan.curves.Curve each) and finds each scan's main-lobe optimum (studies.scan.curve_optima.Optimum).
Its objective is

    J = sum_t w_t m_t^2 + rising_weight sum_(a before b) max(0, f_a - f_b) / f_b*,

m_t = (f_t - f_t*) / f_t* the relative miss of target t (1 when its metric is nowhere positive),
the second sum over neighbouring labels of each ``rising`` list, f* the paper's optima. SciPy's
differential evolution (vectorized: a whole population's scans go to the runner together) or
bounded Nelder-Mead minimise J over the unit cube. Every evaluation is recorded as it finishes
(studies.runtime.evaluation_log) and replayed on a rerun. The best parameter set is then scanned once
more with points every ``refine_hz`` around its optima, for the report.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict
from scipy import optimize

from ..runtime.evaluation_log import EvaluationLog, unit_key
from ..runtime.interrupts import raise_if_stopped
from ..runtime.pools import Runner
from ..scan.curves import Curve, CurveRun, rising_shortfalls, run_all, run_curves, runs_cost
from .calibration_spec import Calibration

RECORD = ConfigDict(extra="forbid", frozen=True)


class TargetResult(BaseModel):
    """One target's scan in an evaluation: its ``label``, the optimum of its main lobe and its global maximum
    (the fields of studies.scan.curve_optima.Optimum.record: SI values), the first failed run's ``error`` and the
    relative ``miss`` of the main-lobe optimum (1 where there is none)."""

    model_config = RECORD
    label: str
    metric: str
    curve: dict[str, Any]
    along: str
    points: int
    failed: int
    best: float | None
    best_value: float | None
    optimum: float | None
    optimum_value: float | None
    peak_at_scan_end: bool | None
    band_80: tuple[float, float] | None
    band_50: tuple[float, float] | None
    global_optimum: float | None
    resonance_hz: float | None
    lobes: int
    value_unit: str
    no_optimum_reason: str | None
    error: str
    miss: float


class CalibrationEvaluation(BaseModel):
    """One evaluated parameter set (a line of ``evaluations.jsonl``): its ``unit`` point, the ``parameters``
    (scene key path -> value), each target's result, the rising penalty, the objective J (module doc) and
    what its scans cost."""

    model_config = RECORD
    unit: tuple[float, ...]
    parameters: dict[str, float]
    targets: tuple[TargetResult, ...]
    rising_penalty: float
    objective: float
    simulations: int
    failed_runs: int
    cpu_time_s: float


Progress = Callable[[CalibrationEvaluation, bool], None]  # (record, replayed)


def target_result(calibration: Calibration, index: int, run: CurveRun) -> TargetResult:
    """The optimum of one target's scan (studies.scan.curve_optima.Optimum.record), its label, the first
    failed run's error and the relative miss of its main-lobe optimum."""
    target = calibration.spec.targets[index]
    optimum = run.optimum(calibration.metric(index))
    main = optimum.optimum
    return TargetResult(label=calibration.labels[index], **optimum.record, error=run.error,
                        miss=1.0 if main is None else (main - target.optimum_hz) / target.optimum_hz)


def rising_penalty(calibration: Calibration, results: list[TargetResult]) -> float:
    """sum over neighbours (a, b) of each rising list of max(0, f_a - f_b) / f_b* (pairs where a
    target has no optimum are left out: their misses already count 1)."""
    paper = {label: t.optimum_hz for label, t in zip(calibration.labels, calibration.spec.targets, strict=True)}
    shortfalls = rising_shortfalls(calibration.spec.rising, {r.label: r.optimum for r in results})
    return sum(max(0.0, shortfall) / paper[b] for _, b, shortfall in shortfalls)


def objective(calibration: Calibration, results: list[TargetResult]) -> tuple[float, float]:
    """(J, its rising penalty) of an evaluation's per-target results (module docstring)."""
    penalty = rising_penalty(calibration, results)
    misses = sum(t.weight * r.miss ** 2 for t, r in zip(calibration.spec.targets, results, strict=True))
    return misses + calibration.spec.rising_weight * penalty, penalty


def target_curves(calibration: Calibration, key: Any, values: dict[str, float],
                  frequencies_hz: Callable[[int], list[float]]) -> list[Curve]:
    """One curve per target: the base scene changed to these parameter values and the target's overrides,
    along the target's frequencies."""
    return [Curve((key, t), calibration.base, calibration.changes(values, t), tuple(frequencies_hz(t)),
                  (calibration.metric(t),)) for t in range(len(calibration.spec.targets))]


class CalibrationEvaluator:
    """J for batches of unit points: recorded points are replayed, the others' scans (every target
    of every point) go to the runner in one batch; each point is recorded as its last scan ends."""

    def __init__(self, calibration: Calibration, runner: Runner, log: EvaluationLog[CalibrationEvaluation],
                 progress: Progress | None = None) -> None:
        self.calibration, self.runner, self.log, self.progress = calibration, runner, log, progress
        self.memo = {unit_key(r.unit): r for r in log.records}
        self.evaluated = self.replayed = self.simulations = 0
        self.cpu_time_s = 0.0

    def __call__(self, units: np.ndarray) -> np.ndarray:
        """J of each row of ``units`` (S, n)."""
        keys = [unit_key(u) for u in units]
        for key in keys:
            if key in self.memo and self.progress:
                self.replayed += 1
                self.progress(self.memo[key], True)
        todo = list(dict.fromkeys(k for k in keys if k not in self.memo))
        self._run(todo)
        return np.array([self.memo[k].objective for k in keys])

    def _run(self, keys: list[tuple[float, ...]]) -> None:
        calibration = self.calibration
        count = len(calibration.spec.targets)
        frequencies = list(calibration.frequencies_hz)
        values = {k: calibration.values(np.array(k)) for k in keys}
        curves = [curve for k in keys for curve in target_curves(calibration, k, values[k], lambda _: frequencies)]
        scans: dict[tuple[float, ...], dict[int, CurveRun]] = {k: {} for k in keys}
        ran: dict[tuple[float, ...], list[CurveRun]] = {k: [] for k in keys}  # distinct scans
        for served, run in run_curves(self.runner, curves):
            key = served[0][0]
            ran[key].append(run)
            scans[key].update({target: run for _, target in served})
            if len(scans[key]) == count:
                self._record(key, values[key], [scans[key][t] for t in range(count)], runs_cost(ran[key]))

    def _record(self, key: tuple[float, ...], values: dict[str, float], runs: list[CurveRun],
                cost: dict[str, Any]) -> None:
        results = [target_result(self.calibration, t, run) for t, run in enumerate(runs)]
        raise_if_stopped()  # scans cut by an interrupt are not an evaluation
        total, penalty = objective(self.calibration, results)
        record = CalibrationEvaluation(unit=key, parameters=values, targets=tuple(results), rising_penalty=penalty,
                                       objective=total, **cost)
        self.log.append(record)
        self.memo[key] = record
        self.evaluated += 1
        self.simulations += cost["simulations"]
        self.cpu_time_s += cost["cpu_time_s"]
        if self.progress:
            self.progress(record, False)


def search(calibration: Calibration, evaluate: Callable[[np.ndarray], np.ndarray]) -> None:
    """Minimise J over the unit cube, starting from the base scene's values."""
    settings, start = calibration.spec.search, calibration.start_unit()
    bounds = [(0.0, 1.0)] * len(start)
    if settings.method == "differential-evolution":
        optimize.differential_evolution(lambda units: evaluate(units.T), bounds, popsize=settings.popsize,
                                        maxiter=settings.max_generations, rng=settings.seed, polish=False,
                                        x0=start, updating="deferred", vectorized=True)
    else:
        optimize.minimize(lambda unit: float(evaluate(unit[None, :])[0]), start, method="Nelder-Mead",
                          bounds=bounds, options={"maxfev": settings.max_evaluations, "xatol": 1e-3, "fatol": 1e-6,
                                                  "initial_simplex": _simplex(start)})


def _simplex(start: np.ndarray) -> np.ndarray:
    """A simplex of steps of 0.25 (a quarter of each parameter's unit range) around the start."""
    points = [start]
    for i in range(len(start)):
        point = start.copy()
        point[i] = point[i] + 0.25 if point[i] <= 0.75 else point[i] - 0.25
        points.append(point)
    return np.array(points)


def refined_frequencies_hz(axis_hz: tuple[float, ...], around_hz: Iterable[float | None], step_hz: float | None) -> list[float]:
    """The scan axis plus points every ``step_hz`` within one axis spacing of each given frequency."""
    points = set(axis_hz)
    spacing = max(b - a for a, b in itertools.pairwise(axis_hz))
    for centre in around_hz if step_hz else ():
        if centre is not None:
            first, last = math.ceil((centre - spacing) / step_hz), math.floor((centre + spacing) / step_hz)
            points |= {float(f"{i * step_hz:.12g}") for i in range(first, last + 1)}
    return sorted(f for f in points if axis_hz[0] <= f <= axis_hz[-1])


@dataclass(frozen=True)
class FinalScan:
    """The best parameter set scanned on the refined axes: per-target results and curves."""

    results: list[TargetResult]
    curves: list[tuple[list[float], list[float]]]  # (frequencies, metric values) per target
    cost: dict[str, Any]  # studies.scan.curves.runs_cost


def final_scan(calibration: Calibration, best: CalibrationEvaluation, runner: Runner) -> FinalScan:
    """Scan every target of the best evaluation again, refined around its main and global optima."""
    axes = [refined_frequencies_hz(calibration.frequencies_hz, (r.optimum, r.global_optimum),
                                   calibration.spec.refine_hz) for r in best.targets]
    curves = target_curves(calibration, "best", best.parameters, lambda t: axes[t])
    runs, cost = run_all(runner, curves)
    results = [target_result(calibration, t, runs[("best", t)]) for t in range(len(curves))]
    values = [(axes[t], runs[("best", t)].values(calibration.metric(t))) for t in range(len(curves))]
    return FinalScan(results, values, cost)


@dataclass(frozen=True)
class SearchResult:
    """Every recorded evaluation, the best one (None if every simulation of every evaluation failed,
    or every run of a target did: ``failed_targets``), its final scan, and what this session cost."""

    records: list[CalibrationEvaluation]
    best: CalibrationEvaluation | None
    final: FinalScan | None
    session: dict[str, Any]
    failed_targets: list[str]


def failed_targets(calibration: Calibration, records: list[CalibrationEvaluation]) -> list[str]:
    """The labels of the targets whose every run failed in every evaluation."""
    count = len(calibration.frequencies_hz)
    return [label for t, label in enumerate(calibration.labels)
            if all(record.targets[t].failed >= count for record in records)]


def _session(evaluator: CalibrationEvaluator, final: FinalScan | None, runner_label: str, start_wall: float,
             interrupted: bool) -> dict[str, Any]:
    return {"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"), "runner": runner_label,
            "interrupted": interrupted, "evaluations_run": evaluator.evaluated,
            "evaluations_replayed": evaluator.replayed,
            "simulations": evaluator.simulations + (final.cost["simulations"] if final else 0),
            "simulation_cpu_time_s": evaluator.cpu_time_s + (final.cost["cpu_time_s"] if final else 0.0),
            "wall_time_s": time.perf_counter() - start_wall}


def search_calibration(calibration: Calibration, runner: Runner, log: EvaluationLog[CalibrationEvaluation],
                       progress: Progress | None = None, runner_label: str = "") -> SearchResult:
    """Search (replaying what ``log`` holds), then scan the best parameter set for the report. An
    interrupted search (Ctrl-C, SIGTERM) records its session before it stops."""
    start_wall = time.perf_counter()
    evaluator = CalibrationEvaluator(calibration, runner, log, progress)
    try:
        search(calibration, evaluator)
        failed = failed_targets(calibration, log.records)
        usable = [r for r in log.records if r.failed_runs < r.simulations]
        best = min(usable, key=lambda r: r.objective) if usable and not failed else None
        final = final_scan(calibration, best, runner) if best else None
    except KeyboardInterrupt:
        log.add_session(_session(evaluator, None, runner_label, start_wall, interrupted=True))
        raise
    session = _session(evaluator, final, runner_label, start_wall, interrupted=False)
    log.add_session(session)
    return SearchResult(list(log.records), best, final, session, failed)
