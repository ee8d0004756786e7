"""Work-precision studies: the YAML schema, its expansion into solver settings, and the worker.

A study names a ``base_scene`` with ``base_overrides`` (as in studies/scan/study.py), a window of
``blows`` impact periods from rest, the number of ``repeats`` (the median CPU time counts), a CPU
``time_limit_s`` per run (default 60 s; a run beyond it is a failed setting), the
``reference`` run and an independent ``reference_check`` run, the ``grid_interval_s`` of the
bit-velocity comparison, and the solver ``families`` to compare. A setting is a scene ``solver``
mapping (models.definition.scene.Solver: the ``formulation`` and its options); a family is one solver (a line
of the plot) swept over one of its keys::

    name: paper_base_workprecision
    base_scene: ../scenes/paper_base.yaml
    base_overrides: {impact.amplitude_n: 400.0e3, impact.frequency_hz: 45.0,
                     metrics: {transient_blows: 2, block_blows: 3}}
    blows: 8
    repeats: 3
    reference: {solver: {formulation: exact}}
    reference_check: {solver: {formulation: ode, method: DOP853, relative_tolerance: 1.0e-12}}
    families:
      - {label: rk44, solver: {formulation: exudyn, type: rk44}, sweep: {step_s: [1.0e-4, 1.0e-5]}}
      - {label: dopri5, solver: {formulation: exudyn, type: dopri5, step_s: 1.0e-4},
         sweep: {relative_tolerance: {from: 1.0e-3, to: 1.0e-9, num: 4, spacing: log}}}
      - {label: presets, solver: {formulation: exudyn}, sweep: {preset: [fast, standard, reference]}}
      - {label: DOP853 (ODE), solver: {formulation: ode, method: DOP853},
         sweep: {relative_tolerance: [1.0e-4, 1.0e-8]}}

A swept ``relative_tolerance`` also sets ``absolute_tolerance`` to ``atol_ratio`` (default 1e-3)
times it unless the setting gives one (the ODE's in the state's SI units). Exudyn runs store every
step; the exact formulation samples at ``grid_interval_s``, the grid of the bit-velocity comparison
(whole multiples of it); the ODE samples its dense output at ``sample_interval_s`` (default 2e-7 s
here, so that interpolating the bit velocity adds about 1e-7 of its range).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import signal
import statistics
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import Field

from ...models.definition.scene import MAX_COUNT, Scene
from ...models.evaluation.results import SimulationResult
from ...models.evaluation.workprecision import (
    ERROR_MEASURES,
    Signature,
    errors,
    pareto_front,
    signature,
    uniform_grid_s,
)
from ...models.solvers.cost import Cause
from ..inputs.reading import InputError, parse, prepare_scene, read_yaml
from ..inputs.specs import Axis, SceneSpec, StrictSpec
from ..runtime.budgets import DEFAULT_BUDGET, Budget, check_size
from ..runtime.resumable import STATUS_COLUMNS, result_row
from ..scan.study import StudyPoint

# Exudyn runs store every step (a write period below any step): the error of a run includes the
# linear interpolation of its own steps onto the grid, not that of a coarser storage interval.
EVERY_STEP_S = 1e-9
ODE_SAMPLE_INTERVAL_S = 2e-7
GRID_POINTS_PER_PULSE = 10  # the bit-velocity comparison grid resolves the impact pulse
MAX_TIME_LIMIT_S = 86400.0  # a day of CPU per run (the timer of cpu_time_limit takes no more than a time_t)
# What the windowed scenes compute: only what the errors need (no energy account, no force sensors).
OUTPUTS = {"metrics": ["penetration_rate_m_per_s"], "timeseries": ["borehole_bottom_m"]}


class Run(StrictSpec):
    """One solver setting: a reference, or the fixed part of a family."""

    solver: dict[str, Any] = Field(default_factory=lambda: {"formulation": "exact"})
    atol_ratio: float = Field(1e-3, gt=0)


class Family(StrictSpec):
    """A line of the plot: one solver swept over one setting."""

    label: str
    solver: dict[str, Any]
    sweep: dict[str, Axis] = Field(min_length=1, max_length=1)
    atol_ratio: float = Field(1e-3, gt=0)
    repeats: int | None = Field(None, ge=1, le=MAX_COUNT)


class AccuracySpec(SceneSpec):
    """The study file as written."""

    blows: int = Field(ge=1, le=MAX_COUNT)
    repeats: int = Field(3, ge=1, le=MAX_COUNT)
    grid_interval_s: float = Field(1e-5, gt=0)
    time_limit_s: float = Field(60.0, gt=0, le=MAX_TIME_LIMIT_S)
    reference: Run = Run()
    reference_check: Run | None = None
    families: list[Family] = Field(min_length=1)
    format: Literal["png", "svg", "pdf"] = "png"


@dataclass(frozen=True)
class Setting:
    """A run of the study: a scene ``solver`` mapping (formulation and options) and its repeats."""

    solver: dict[str, Any]
    repeats: int

    @property
    def formulation(self) -> str:
        return self.solver.get("formulation", "exudyn")


@dataclass(frozen=True)
class AccuracyStudy:
    """A validated study (duck-typed like studies.scan.study.Study for the shared provenance and resume code)."""

    source: Path
    spec: AccuracySpec
    base: dict[str, Any]
    scene: dict[str, Any]  # the windowed scene every setting runs
    points: list[StudyPoint]
    runs: list[Setting]  # runs[i] belongs to points[i]
    reference: Setting
    reference_check: Setting | None

    def resolved(self) -> dict[str, Any]:
        data = self.spec.model_dump(mode="json", by_alias=True)
        data.update(base_scene=Scene.model_validate(self.scene).model_dump(mode="json", by_alias=True),
                    settings=[{**p.parameters, **r.solver} for p, r in zip(self.points, self.runs)])
        return data

    @property
    def hash(self) -> str:
        content = {"scene": self.scene, "grid_interval_s": self.spec.grid_interval_s,
                   "runs": [[r.solver, r.repeats] for r in self.runs], "reference": self.reference.solver}
        return hashlib.sha256(json.dumps(content, sort_keys=True, default=str).encode()).hexdigest()


def windowed_scene(base: dict[str, Any], blows: int) -> dict[str, Any]:
    """The base scene over ``blows`` periods, computing only the penetration rate and x_n (not validated)."""
    scene = json.loads(json.dumps(base))
    period = 1.0 / Scene.model_validate(base).impact.frequency_hz
    scene["solver"] = {"end_time_s": blows * period}
    scene["outputs"] = OUTPUTS
    return scene


def scene_for(study: AccuracyStudy | dict[str, Any], setting: Setting, grid_interval_s: float) -> dict[str, Any]:
    """The windowed scene with the setting's solver: Exudyn storing every step, the exact solver
    sampling the comparison grid, the ODE's dense output at ODE_SAMPLE_INTERVAL_S unless given."""
    data = json.loads(json.dumps(study))
    storage = {"exact": grid_interval_s, "ode": grid_interval_s}.get(setting.formulation, EVERY_STEP_S)
    defaults = {"sample_interval_s": ODE_SAMPLE_INTERVAL_S} if setting.formulation == "ode" else {}
    data["solver"] = {**data["solver"], "output_interval_s": storage, **defaults, **setting.solver}
    return data


def _setting(fixed: dict[str, Any], key: str | None, value: Any, atol_ratio: float, repeats: int) -> Setting:
    solver = {**fixed, **({key: value} if key else {})}
    if key == "relative_tolerance" and "absolute_tolerance" not in fixed and type(value) in (int, float):
        solver["absolute_tolerance"] = float(f"{value * atol_ratio:.6g}")
    return Setting(solver, repeats)


def _checked(setting: Setting, scene: dict[str, Any], spec: AccuracySpec, source: str, key: str,
             budget: Budget) -> tuple[float, str]:
    """(The estimated CPU seconds of the setting's runs (each at most ``time_limit_s``), its solver as
    resolved: the Exudyn solver type, a preset's included, the ODE method, or the formulation);
    InputError naming ``source`` and ``key`` unless its windowed scene validates and prepares,
    BudgetError beyond the run budget."""
    grid, where = spec.grid_interval_s, f"{source}: {key}"
    simulation = prepare_scene(parse(Scene, scene_for(scene, setting, grid), where, ()), where)
    cost = budget.check_run(simulation, source, f"{key}, over blows: {spec.blows}: ",
                            resampled=Cause("grid_interval_s", grid))
    solver = getattr(simulation.settings, "type", None) or getattr(simulation.settings, "method", setting.formulation)
    return setting.repeats * min(cost.cpu_s, spec.time_limit_s), solver


def load_accuracy_study(path: str | Path, budget: Budget = DEFAULT_BUDGET) -> AccuracyStudy:
    """Read, validate and expand a work-precision study, every run checked against the ``budget``;
    InputError naming file and key, BudgetError naming the cost, otherwise."""
    path = Path(path)
    source = str(path)
    spec = parse(AccuracySpec, read_yaml(path), source)
    base = spec.base_scene_dict(path)
    scene = windowed_scene(base, spec.blows)
    pulse_s = parse(Scene, scene, f"{path} (base scene over blows: {spec.blows})").impact.duration_s
    if spec.grid_interval_s > pulse_s / GRID_POINTS_PER_PULSE:
        raise InputError(f"{source}: grid_interval_s: {spec.grid_interval_s:g}: the comparison grid must resolve "
                         f"the pulse: at most impact.duration_s / {GRID_POINTS_PER_PULSE} = "
                         f"{pulse_s / GRID_POINTS_PER_PULSE:.3g} s")
    count = sum(axis.count for family in spec.families for axis in family.sweep.values())
    what = f"families: {count:.6g} settings x repeats, over blows: {spec.blows}"
    check_size(budget, source, what, count, 0.0)
    points, runs = [], []
    for i, family in enumerate(spec.families):
        (key, axis), = family.sweep.items()
        for value in axis.expand():
            setting = _setting(family.solver, key, value, family.atol_ratio, family.repeats or spec.repeats)
            cpu, solver = _checked(setting, scene, spec, source, f"families.{i}.sweep.{key}: {value!r}", budget)
            points.append(StudyPoint(len(points), {"family": family.label, "formulation": setting.formulation,
                                              "solver": solver, "setting": key, "value": value}, None, cpu))
            runs.append(setting)
    references = [None if run is None else _setting(run.solver, None, None, run.atol_ratio, 1)
                  for run in (spec.reference, spec.reference_check)]
    cpu = [_checked(setting, scene, spec, source, key, budget)[0]
           for setting, key in zip(references, ("reference", "reference_check")) if setting is not None]
    budget.check_total(source, what, sum(r.repeats for r in runs) + len(cpu), sum(p.cpu_s for p in points) + sum(cpu))
    return AccuracyStudy(path, spec, base, scene, points, runs, *references)


def simulate_setting(scene: dict[str, Any], setting: Setting, grid_interval_s: float) -> SimulationResult:
    """One run of the windowed ``scene`` with ``setting`` (StepLimitWarnings silenced: a diverged
    run is reported as SimulationFailed by the formulation)."""
    from ...models.solvers.simulation import prepare

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare(Scene.model_validate(scene_for(scene, setting, grid_interval_s))).run()


class TimeLimitExceeded(RuntimeError):
    """A run used more CPU time than the study allows (e.g. an automatic step stuck at its minimum)."""


@contextlib.contextmanager
def cpu_time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`TimeLimitExceeded` once the process has used ``seconds`` more CPU time.

    SIGPROF is handled when Python next runs: inside the Exudyn model that is its per-step hook (the
    rock's return mapping of a crushing rock), which makes the solver stop with an error naming the
    exception; without any Python code per step the limit takes effect when the solver returns.
    Main thread only (worker processes and the sequential runner run there)."""
    def expire(signum: int, frame: Any) -> None:
        raise TimeLimitExceeded(f"run exceeded the study's CPU time limit of {seconds:g} s (time_limit_s)")

    previous = signal.signal(signal.SIGPROF, expire)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)


def run_setting(task: tuple[int, dict[str, Any], Setting, float, float]) -> dict[str, Any]:
    """Worker: ``(index, windowed scene, setting, grid interval, CPU time limit per run)`` run
    ``repeats`` times; the outcome carries the :class:`Signature` of the first run and every CPU
    time. A failure (SimulationFailed, the time limit or any exception) is returned, not raised."""
    index, scene, setting, grid_interval_s, limit_s = task
    start = time.perf_counter()
    cpu, sig = [], None
    try:
        for _ in range(setting.repeats):
            with cpu_time_limit(limit_s):
                result = simulate_setting(scene, setting, grid_interval_s)
            cpu.append(result.cpu_time_s)
            if sig is None:
                sig = signature(result, uniform_grid_s(result.scene.solver.end_time_s, grid_interval_s))
    except Exception as err:  # noqa: BLE001 - a failed setting is a result of the study
        message = f"{type(err).__name__}: {err}"
        if "TimeLimitExceeded" in message:  # raised inside an Exudyn user function: wrapped
            message = f"TimeLimitExceeded: run exceeded the study's CPU time limit of {limit_s:g} s (time_limit_s)"
        return {"point": index, "status": "failed", "error": message,
                "wall_time_s": time.perf_counter() - start, "metrics": {}, "signature": None}
    return {"point": index, "status": "ok", "error": "", "wall_time_s": time.perf_counter() - start,
            "metrics": {"cpu_time_s": statistics.median(cpu), "cpu_time_s_runs": ";".join(f"{c:.4g}" for c in cpu)},
            "signature": sig}


def reference_signature(study: AccuracyStudy, setting: Setting) -> Signature:
    """Run a reference setting once in this process (its failure propagates)."""
    result = simulate_setting(study.scene, setting, study.spec.grid_interval_s)
    return signature(result, uniform_grid_s(result.scene.solver.end_time_s, study.spec.grid_interval_s))


PARAMETERS = ("family", "formulation", "solver", "setting", "value")
VALUES = ("cpu_time_s", "cpu_time_s_runs", "bottom_end_error_m", *ERROR_MEASURES, "penetration_rate_m_per_s")
COLUMNS = ["point", *PARAMETERS, *STATUS_COLUMNS, *VALUES]
PARETO_COLUMNS = ("measure", "point", *PARAMETERS, "cpu_time_s", "error")
Row = dict[str, str]


def outcome_row(study: AccuracyStudy, reference: Signature, outcome: dict[str, Any]) -> dict[str, Any]:
    """The CSV row of a finished setting, its errors measured against ``reference``."""
    if outcome["status"] == "ok":
        sig: Signature = outcome["signature"]
        outcome["metrics"].update({k: f"{v:.6g}" for k, v in errors(reference, sig).items()},
                                  penetration_rate_m_per_s=f"{sig.penetration_rate_m_per_s:.10g}")
        outcome["metrics"]["cpu_time_s"] = f"{outcome['metrics']['cpu_time_s']:.6g}"
    return result_row(study.points[outcome["point"]], outcome)


def number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def pareto_rows(rows: list[Row]) -> list[dict[str, Any]]:
    """The Pareto front of every error measure over the settings that ran."""
    ok = [r for r in rows if r["status"] == "ok"]
    out = []
    for measure in ERROR_MEASURES:
        cost, error = [number(r["cpu_time_s"]) for r in ok], [number(r[measure]) for r in ok]
        for i in pareto_front(cost, error):
            out.append({"measure": measure, **{k: ok[i][k] for k in ("point", *PARAMETERS)},
                        "cpu_time_s": ok[i]["cpu_time_s"], "error": ok[i][measure]})
    return out


def smallest_errors(rows: list[Row]) -> dict[str, float]:
    """The smallest positive error of each measure over the settings that ran (what the plot shows)."""
    out = {}
    for measure in ERROR_MEASURES:
        values = [v for v in (number(r[measure]) for r in rows if r["status"] == "ok") if v > 0 and math.isfinite(v)]
        out[measure] = min(values, default=math.nan)
    return out


def reference_report(study: AccuracyStudy, reference: Signature, check: Signature | None,
                     rows: list[Row]) -> dict[str, Any]:
    """Both references, their agreement per measure and whether it is below the smallest plotted error."""
    report: dict[str, Any] = {
        "reference": {**study.reference.solver,
                      "cpu_time_s": reference.cpu_time_s, "bottom_end_m": reference.bottom_end_m,
                      "penetration_rate_m_per_s": reference.penetration_rate_m_per_s},
        "smallest_plotted_error": smallest_errors(rows),
    }
    if check is None or study.reference_check is None:
        return report
    agreement = errors(reference, check)
    report["reference_check"] = {
                                 **study.reference_check.solver, "cpu_time_s": check.cpu_time_s}
    report["agreement"] = agreement
    report["agreement_below_smallest_error"] = {
        m: bool(not math.isfinite(report["smallest_plotted_error"][m])
                or agreement[m] < report["smallest_plotted_error"][m]) for m in ERROR_MEASURES}
    return report


