"""Work-precision studies: the YAML schema, its expansion into solver settings, and the worker.

A study names a ``base_scene`` with ``base_overrides`` (as in studies/study.py), a window of
``blows`` impact periods from rest, the number of ``repeats`` (the median CPU time counts), a CPU
``time_limit_s`` per run (default 60 s; a run beyond it is a failed setting), the
``reference`` run and an independent ``reference_check`` run, the ``grid_interval_s`` of the
bit-velocity comparison, and the solver ``families`` to compare. A family is one solver (a line
of the plot) swept over one setting::

    name: paper_base_workprecision
    base_scene: ../scenes/paper_base.yaml
    base_overrides: {impact.amplitude_n: 400.0e3, impact.frequency_hz: 45.0,
                     metrics: {transient_blows: 2, block_blows: 3}}
    blows: 8
    repeats: 3
    reference: {formulation: exact}
    reference_check: {formulation: ode, method: DOP853, rtol: 1.0e-12}
    families:
      - {label: rk44, formulation: exudyn, solver: {type: rk44}, sweep: {step_s: [1.0e-4, 1.0e-5]}}
      - {label: dopri5, formulation: exudyn, solver: {type: dopri5, step_s: 1.0e-4},
         sweep: {relative_tolerance: {from: 1.0e-3, to: 1.0e-9, num: 4, spacing: log}}}
      - {label: presets, formulation: exudyn, sweep: {preset: [fast, standard, reference]}}
      - {label: DOP853 (ODE), formulation: ode, solver: {method: DOP853}, sweep: {rtol: [1.0e-4, 1.0e-8]}}

``formulation: exudyn``: ``solver`` and ``sweep`` keys are scene ``solver`` keys
(models.scene.Solver); a swept ``relative_tolerance`` also sets ``absolute_tolerance`` to
``atol_ratio`` (default 1e-3) times it unless the family gives one. ``formulation: ode``: keys
``method`` (DOP853, Radau, LSODA), ``rtol``, ``atol`` (default ``atol_ratio`` * rtol, SI units of
the state) and ``sample_interval_s`` (dense-output sampling, default 2e-7 s so that interpolating
the bit velocity adds about 1e-7 of its range). ``formulation: exact``: models.exact_model, no settings.
Exudyn runs store every step; the exact formulation samples at ``grid_interval_s``, the grid of
the bit-velocity comparison (whole multiples of it).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import signal
import statistics
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import Field
from rpdrill.models.formulations import FORMULATIONS
from rpdrill.models.ode_model import ODE_METHODS, simulate_ode
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Scene
from rpdrill.models.workprecision import Signature, signature, uniform_grid_s
from rpdrill.studies.loading import InputError, parse, read_yaml
from rpdrill.studies.study import Axis, Point, StrictSpec, base_scene_dict, check_formulation

Formulation = Literal[tuple(FORMULATIONS)]  # type: ignore[valid-type]
ODE_KEYS = ("method", "rtol", "atol", "atol_ratio", "sample_interval_s")
ODE_DEFAULTS: dict[str, Any] = {"method": "DOP853", "atol_ratio": 1e-3, "sample_interval_s": 2e-7}
# Exudyn runs store every step (a write period below any step): the error of a run includes the
# linear interpolation of its own steps onto the grid, not that of a coarser storage interval.
EVERY_STEP_S = 1e-9
# What the windowed scenes compute: only what the errors need (no energy account, no force sensors).
OUTPUTS = {"metrics": ["penetration_rate_m_per_s"], "timeseries": ["borehole_bottom_m"]}


class Run(StrictSpec):
    """One solver setting: a reference or a fixed part of a family."""

    formulation: Formulation
    solver: dict[str, Any] = Field(default_factory=dict)
    atol_ratio: float = Field(1e-3, gt=0)
    method: str | None = None
    rtol: float | None = Field(None, gt=0)
    atol: float | None = Field(None, gt=0)
    sample_interval_s: float | None = Field(None, gt=0)


class Family(StrictSpec):
    """A line of the plot: one solver swept over one setting."""

    label: str
    formulation: Formulation
    solver: dict[str, Any] = Field(default_factory=dict)
    sweep: dict[str, Axis] = Field(min_length=1, max_length=1)
    atol_ratio: float = Field(1e-3, gt=0)
    repeats: int | None = Field(None, ge=1)


class AccuracySpec(StrictSpec):
    """The study file as written."""

    name: str
    description: str = ""
    base_scene: str | dict[str, Any]
    base_overrides: dict[str, Any] = Field(default_factory=dict)
    blows: int = Field(ge=1)
    repeats: int = Field(3, ge=1)
    grid_interval_s: float = Field(1e-5, gt=0)
    time_limit_s: float = Field(60.0, gt=0)
    reference: Run = Run(formulation="exact")
    reference_check: Run | None = None
    families: list[Family] = Field(min_length=1)
    format: Literal["png", "svg", "pdf"] = "png"


@dataclass(frozen=True)
class Setting:
    """A run of the study: formulation, solver settings (Exudyn: scene solver keys; ode: ODE_KEYS)."""

    formulation: str
    settings: dict[str, Any]
    repeats: int


@dataclass(frozen=True)
class AccuracyStudy:
    """A validated study (duck-typed like studies.study.Study for the shared provenance and resume code)."""

    source: Path
    spec: AccuracySpec
    base: dict[str, Any]
    scene: dict[str, Any]  # the windowed scene every setting runs
    points: list[Point]
    runs: list[Setting]  # runs[i] belongs to points[i]
    reference: Setting
    reference_check: Setting | None

    def resolved(self) -> dict[str, Any]:
        data = self.spec.model_dump(mode="json", by_alias=True)
        data.update(base_scene=Scene.model_validate(self.scene).model_dump(mode="json", by_alias=True),
                    settings=[{**p.parameters, **r.settings} for p, r in zip(self.points, self.runs)])
        return data

    @property
    def hash(self) -> str:
        content = {"scene": self.scene, "grid_interval_s": self.spec.grid_interval_s,
                   "runs": [[r.formulation, r.settings, r.repeats] for r in self.runs],
                   "reference": [self.reference.formulation, self.reference.settings]}
        return hashlib.sha256(json.dumps(content, sort_keys=True, default=str).encode()).hexdigest()


def windowed_scene(base: dict[str, Any], blows: int, grid_interval_s: float) -> dict[str, Any]:
    """The base scene over ``blows`` periods from rest, stored at ``grid_interval_s``, computing only
    the penetration rate and x_n (the windowed scene dict, not validated)."""
    scene = json.loads(json.dumps(base))
    period = 1.0 / Scene.model_validate(base).impact.frequency_hz
    solver = scene.setdefault("solver", {})
    solver.update(end_time_s=blows * period, output_interval_s=grid_interval_s)
    scene["outputs"] = OUTPUTS
    return scene


def _scene_for(scene: dict[str, Any], settings: dict[str, Any]) -> dict[str, Any]:
    """The scene dict with the Exudyn solver settings (a preset replaces every accuracy key)."""
    data = json.loads(json.dumps(scene))
    data["solver"] = {"end_time_s": data["solver"]["end_time_s"], "output_interval_s": EVERY_STEP_S, **settings}
    return data


def _setting(formulation: str, fixed: dict[str, Any], key: str | None, value: Any, atol_ratio: float,
             repeats: int) -> Setting:
    settings = {**fixed, **({key: value} if key else {})}
    if formulation == "exudyn" and key == "relative_tolerance" and "absolute_tolerance" not in fixed:
        settings["absolute_tolerance"] = float(f"{value * atol_ratio:.6g}")
    if formulation == "ode":
        settings = {**ODE_DEFAULTS, **settings}
        settings.setdefault("atol", float(f"{settings['rtol'] * settings.pop('atol_ratio'):.6g}"))
        settings.pop("atol_ratio", None)
    return Setting(formulation, settings, repeats)


def _check_setting(setting: Setting, scene: dict[str, Any], where: str) -> None:
    if setting.formulation == "exudyn":
        parse(Scene, _scene_for(scene, setting.settings), f"{where} (solver settings)", ("solver",))
    elif setting.formulation == "ode":
        unknown = [k for k in setting.settings if k not in ODE_KEYS]
        if unknown:
            raise InputError(f"{where}: {unknown[0]!r}: unknown ODE setting; allowed: {', '.join(ODE_KEYS)}")
        if setting.settings["method"] not in ODE_METHODS:
            raise InputError(f"{where}: method: {setting.settings['method']!r}: not one of {', '.join(ODE_METHODS)}")
        if "rtol" not in setting.settings:
            raise InputError(f"{where}: rtol: missing: an ODE run needs a relative tolerance")
    elif setting.settings:
        raise InputError(f"{where}: the exact formulation takes no solver settings")
    check_formulation(where, "formulation", setting.formulation, scene)


def _run_setting(run: Run) -> Setting:
    fixed = dict(run.solver)
    for key in ("method", "rtol", "atol", "sample_interval_s"):
        if getattr(run, key) is not None:
            fixed[key] = getattr(run, key)
    if run.formulation == "ode":
        fixed.setdefault("atol_ratio", run.atol_ratio)
    return _setting(run.formulation, fixed, None, None, run.atol_ratio, 1)


def load_accuracy_study(path: str | Path) -> AccuracyStudy:
    """Read, validate and expand a work-precision study; InputError naming file and key otherwise."""
    path = Path(path)
    spec = parse(AccuracySpec, read_yaml(path), str(path))
    base = base_scene_dict(spec, path)
    scene = windowed_scene(base, spec.blows, spec.grid_interval_s)
    parse(Scene, scene, f"{path} (base scene over blows: {spec.blows})")
    points, runs = [], []
    for i, family in enumerate(spec.families):
        (key, axis), = family.sweep.items()
        fixed = {**family.solver, **({"atol_ratio": family.atol_ratio} if family.formulation == "ode" else {})}
        for value in axis.expand():
            setting = _setting(family.formulation, fixed, key, value, family.atol_ratio,
                               family.repeats or spec.repeats)
            _check_setting(setting, scene, f"{path}: families.{i}.sweep.{key}: {value!r}")
            solver = setting.settings.get("type", "rk44") if family.formulation == "exudyn" \
                else setting.settings.get("method", "exact")
            points.append(Point(len(points), {"family": family.label, "formulation": family.formulation,
                                              "solver": solver, "setting": key, "value": value}, scene, {}))
            runs.append(setting)
    reference = _run_setting(spec.reference)
    _check_setting(reference, scene, f"{path}: reference")
    check = _run_setting(spec.reference_check) if spec.reference_check else None
    if check:
        _check_setting(check, scene, f"{path}: reference_check")
    return AccuracyStudy(path, spec, base, scene, points, runs, reference, check)


def simulate_setting(scene: dict[str, Any], setting: Setting) -> SimulationResult:
    """One run of the windowed ``scene`` with ``setting`` (StepLimitWarnings silenced: a diverged
    run is reported as SimulationFailed by the formulation)."""
    from rpdrill.models.exact_model import simulate_exact
    from rpdrill.models.exudyn_model import simulate_exudyn

    if setting.formulation == "exudyn":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return simulate_exudyn(Scene.model_validate(_scene_for(scene, setting.settings)))
    validated = Scene.model_validate(scene)
    if setting.formulation == "ode":
        s = setting.settings
        return simulate_ode(validated, s["method"], s["rtol"], s["atol"], s["sample_interval_s"])
    return simulate_exact(validated)


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
                result = simulate_setting(scene, setting)
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
    result = simulate_setting(study.scene, setting)
    return signature(result, uniform_grid_s(result.scene.solver.end_time_s, study.spec.grid_interval_s))
