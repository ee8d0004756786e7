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
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

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
from ...models.runs.scene_run import run
from ...models.solvers.cost import Cause
from ...models.solvers.simulation import prepare
from ..inputs.reading import InputError, parse, prepare_scene, read_yaml
from ..inputs.shipped import shipped_path
from ..inputs.specs import Axis, SceneSpec, StrictSpec
from ..runtime.budgets import DEFAULT_BUDGET, Budget, check_size
from ..runtime.point_runs import STATUS_COLUMNS
from ..runtime.resumable import point_row

if TYPE_CHECKING:
    import pandas as pd

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
class AccuracyPoint:
    """A setting of the study as a point of its table: its index, the ``values`` its row starts with
    (PARAMETERS: family, formulation, solver as resolved, setting, value) and its estimated CPU seconds."""

    index: int
    values: dict[str, Any]
    cpu_s: float


@dataclass(frozen=True)
class AccuracyStudy:
    """A validated study (duck-typed like studies.scan.study.Study for the shared provenance and resume code)."""

    source: Path
    spec: AccuracySpec
    base: Scene
    scene: Scene  # the windowed scene every setting runs
    points: list[AccuracyPoint]
    runs: list[Setting]  # runs[i] belongs to points[i]
    reference: Setting
    reference_check: Setting | None

    def resolved(self) -> dict[str, Any]:
        data = self.spec.model_dump(mode="json", by_alias=True)
        data.update(base_scene=self.scene.model_dump(mode="json", by_alias=True),
                    settings=[{**p.values, **r.solver} for p, r in zip(self.points, self.runs)])
        return data

    @property
    def hash(self) -> str:
        content = {"scene": self.scene.model_dump(mode="json", by_alias=True, exclude_none=True),
                   "grid_interval_s": self.spec.grid_interval_s,
                   "runs": [[r.solver, r.repeats] for r in self.runs], "reference": self.reference.solver}
        return hashlib.sha256(json.dumps(content, sort_keys=True, default=str).encode()).hexdigest()


def windowed_scene(base: Scene, blows: int, source: str) -> Scene:
    """The base scene over ``blows`` periods (its solver's defaults), computing only the penetration rate and
    x_n; InputError naming ``source`` when that is no valid scene."""
    return base.with_({"solver": {"end_time_s": blows * base.impact.period_s}, "outputs": OUTPUTS}, source)


def scene_for(scene: Scene, setting: Setting, grid_interval_s: float, source: str = "accuracy") -> Scene:
    """The windowed scene with the setting's solver: Exudyn storing every step, the exact solver
    sampling the comparison grid, the ODE's dense output at ODE_SAMPLE_INTERVAL_S unless given."""
    storage = {"exact": grid_interval_s, "ode": grid_interval_s}.get(setting.formulation, EVERY_STEP_S)
    defaults = {"sample_interval_s": ODE_SAMPLE_INTERVAL_S} if setting.formulation == "ode" else {}
    solver = {"end_time_s": scene.solver.end_time_s, "output_interval_s": storage, **defaults, **setting.solver}
    return scene.with_({"solver": solver}, source)


def _setting(fixed: dict[str, Any], key: str | None, value: Any, atol_ratio: float, repeats: int) -> Setting:
    solver = {**fixed, **({key: value} if key else {})}
    if key == "relative_tolerance" and "absolute_tolerance" not in fixed and type(value) in (int, float):
        solver["absolute_tolerance"] = float(f"{value * atol_ratio:.6g}")
    return Setting(solver, repeats)


def _checked(setting: Setting, scene: Scene, spec: AccuracySpec, source: str, key: str,
             budget: Budget) -> tuple[float, str]:
    """(The estimated CPU seconds of the setting's runs (each at most ``time_limit_s``), its solver as
    resolved: the Exudyn solver type, a preset's included, the ODE method, or the formulation);
    InputError naming ``source`` and ``key`` unless its windowed scene validates and prepares,
    BudgetError beyond the run budget."""
    grid, where = spec.grid_interval_s, f"{source}: {key}"
    simulation = prepare_scene(scene_for(scene, setting, grid, where), where)
    cost = budget.check_run(simulation, source, f"{key}, over blows: {spec.blows}: ",
                            resampled=Cause("grid_interval_s", grid))
    solver = getattr(simulation.settings, "type", None) or getattr(simulation.settings, "method", setting.formulation)
    return setting.repeats * min(cost.cpu_s, spec.time_limit_s), solver


def load_accuracy_study(path: str | Path, budget: Budget = DEFAULT_BUDGET, allow_code: Sequence[str] | str = ()) -> AccuracyStudy:
    """Read, validate and expand a work-precision study (``allow_code``: the modules of one's own its scene
    may run), every run checked against the ``budget``;
    InputError naming file and key, BudgetError naming the cost, otherwise."""
    path = Path(shipped_path(path, "accuracy", "rpdrill.load_accuracy_study"))
    source = str(path)
    spec = parse(AccuracySpec, read_yaml(path), source)
    base = spec.base(path, allow_code)
    scene = windowed_scene(base, spec.blows, f"{path} (base scene over blows: {spec.blows})")
    pulse_s = scene.impact.duration_s
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
            points.append(AccuracyPoint(len(points), {"family": family.label, "formulation": setting.formulation,
                                                      "solver": solver, "setting": key, "value": value}, cpu))
            runs.append(setting)
    references = [None if run is None else _setting(run.solver, None, None, run.atol_ratio, 1)
                  for run in (spec.reference, spec.reference_check)]
    cpu = [_checked(setting, scene, spec, source, key, budget)[0]
           for setting, key in zip(references, ("reference", "reference_check")) if setting is not None]
    budget.check_total(source, what, sum(r.repeats for r in runs) + len(cpu), sum(p.cpu_s for p in points) + sum(cpu))
    return AccuracyStudy(path, spec, base, scene, points, runs, *references)


def simulate_setting(scene: Scene, setting: Setting, grid_interval_s: float) -> SimulationResult:
    """One run of the windowed ``scene`` with ``setting`` (StepLimitWarnings silenced: a diverged
    run is reported as SimulationFailed by the formulation)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run(prepare(scene_for(scene, setting, grid_interval_s))).raw


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


def run_setting(task: tuple[Scene, Setting, float, float]) -> dict[str, Any]:
    """Worker: ``(windowed scene, setting, grid interval, CPU time limit per run)`` run ``repeats`` times;
    the outcome carries the :class:`Signature` of the first run and every CPU time. A failure
    (SimulationFailed, the time limit or any exception) is returned, not raised."""
    scene, setting, grid_interval_s, limit_s = task
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
        return {"status": "failed", "error": message, "wall_time_s": time.perf_counter() - start, "signature": None}
    return {"status": "ok", "error": "", "wall_time_s": time.perf_counter() - start,
            "cpu_time_s": statistics.median(cpu), "cpu_time_s_runs": ";".join(f"{c:.4g}" for c in cpu), "signature": sig}


def reference_signature(study: AccuracyStudy, setting: Setting) -> Signature:
    """Run a reference setting once in this process (its failure propagates)."""
    result = simulate_setting(study.scene, setting, study.spec.grid_interval_s)
    return signature(result, uniform_grid_s(result.scene.solver.end_time_s, study.spec.grid_interval_s))


PARAMETERS = ("family", "formulation", "solver", "setting", "value")
VALUES = ("cpu_time_s", "cpu_time_s_runs", "bottom_end_error_m", *ERROR_MEASURES, "penetration_rate_m_per_s")
COLUMNS = ["point", *PARAMETERS, *STATUS_COLUMNS, *VALUES]
TEXT = ("family", "formulation", "solver", "setting", "value", "cpu_time_s_runs")  # text even where they read as numbers
# how the table writes its numbers: 6 digits, the penetration rate 10
FORMATS = {"cpu_time_s": ".6g", "bottom_end_error_m": ".6g", **dict.fromkeys(ERROR_MEASURES, ".6g"),
           "penetration_rate_m_per_s": ".10g"}
PARETO_COLUMNS = ("measure", "point", *PARAMETERS, "cpu_time_s", "error")


def outcome_row(study: AccuracyStudy, reference: Signature, point: AccuracyPoint, outcome: dict[str, Any]) -> dict[str, Any]:
    """The table row of a finished setting, its errors measured against ``reference``."""
    values = {key: value for key, value in outcome.items() if key != "signature"}
    if outcome["status"] == "ok":
        sig: Signature = outcome["signature"]
        values.update(errors(reference, sig), penetration_rate_m_per_s=sig.penetration_rate_m_per_s)
    return point_row(point, values)


def pareto_rows(table: pd.DataFrame) -> pd.DataFrame:
    """The Pareto front of every error measure over the settings that ran (PARETO_COLUMNS)."""
    import pandas as pd

    ok = table[table["status"] == "ok"]
    out = []
    for measure in ERROR_MEASURES:
        for i in pareto_front(ok["cpu_time_s"].to_numpy(dtype=float), ok[measure].to_numpy(dtype=float)):
            row = ok.iloc[i]
            out.append({"measure": measure, **{k: row[k] for k in ("point", *PARAMETERS)},
                        "cpu_time_s": row["cpu_time_s"], "error": row[measure]})
    return pd.DataFrame(out, columns=list(PARETO_COLUMNS))


def smallest_errors(table: pd.DataFrame) -> dict[str, float]:
    """The smallest positive error of each measure over the settings that ran (what the plot shows)."""
    ok = table[table["status"] == "ok"]
    out = {}
    for measure in ERROR_MEASURES:
        values = [v for v in ok[measure].to_numpy(dtype=float) if v > 0 and math.isfinite(v)]
        out[measure] = min(values, default=math.nan)
    return out


def reference_report(study: AccuracyStudy, reference: Signature, check: Signature | None,
                     table: pd.DataFrame) -> dict[str, Any]:
    """Both references, their agreement per measure and whether it is below the smallest plotted error."""
    report: dict[str, Any] = {
        "reference": {**study.reference.solver,
                      "cpu_time_s": reference.cpu_time_s, "bottom_end_m": reference.bottom_end_m,
                      "penetration_rate_m_per_s": reference.penetration_rate_m_per_s},
        "smallest_plotted_error": smallest_errors(table),
    }
    if check is None or study.reference_check is None:
        return report
    agreement = errors(reference, check)
    report["reference_check"] = {**study.reference_check.solver, "cpu_time_s": check.cpu_time_s}
    report["agreement"] = agreement
    report["agreement_below_smallest_error"] = {
        m: bool(not math.isfinite(report["smallest_plotted_error"][m])
                or agreement[m] < report["smallest_plotted_error"][m]) for m in ERROR_MEASURES}
    return report
