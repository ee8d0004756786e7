"""The calibration file: what to fit, within which bounds and why, and the paper's optima to reach.

A calibration names a base scene (as a study does; its ``solver.formulation`` runs every point,
e.g. ``base_overrides: {solver.formulation: exact}``), the ``frequency_hz`` axis scanned for every
target, the default ``metric`` whose maximum is the optimum, and:

* ``parameters``: dotted scene path -> ``{bounds: [lo, hi], scale: linear|log, reason: "..."}``;
  a reason is required, bounds are finite with lo < hi (log scale: lo > 0). A name that starts with
  ``$`` (``$impulse_n``) is a *free* parameter: no scene key of the base scene, it enters only the
  targets whose ``overrides`` give it as a value (``{impact.amplitude_n: $impulse_n}``), so one
  fitted value can feed several targets' overrides (the search starts it at the middle of its bounds);
* ``targets``: scene ``overrides``, ``metric``, the paper's ``optimum_hz`` (centre of its band),
  optional ``band_hz: [lo, hi]``, ``label``, ``weight`` (1) and ``tolerance`` (0.15: within 15 %
  of the centre);
* ``rising``: lists of target labels whose main-lobe optima must increase in that order, with
  ``rising_weight`` on the penalty;
* ``search``: ``method`` (``differential-evolution``: ``popsize``, ``max_generations``, ``seed``;
  ``nelder-mead``: ``max_evaluations``);
* ``refine_hz``: step of the scan around each optimum of the best parameter set, for the report.

The search works in unit coordinates u in [0, 1]^n: value = lo + u (hi - lo), or lo (hi/lo)^u on
a log scale. Example: ``studies/paper/calibration.yaml``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
from collections.abc import Sequence
from pathlib import Path
from types import UnionType
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, field_at, parse
from ..inputs.reading import read_yaml
from ..inputs.shipped import shipped_path
from ..inputs.specs import MAX_NUM, Axis, MetricName, SceneSpec, StrictSpec, check_scene_path, scene_value
from ..runtime.budgets import (
    AXIS_VALUE_BYTES,
    DEFAULT_BUDGET,
    EVALUATION_BYTES,
    Budget,
    base_estimate_s,
)
from ..runtime.point_runs import prepare_point
from ..scan.curve_optima import FREQUENCY
from ..scan.curves import Scan

PositiveFloat = Annotated[float, Field(gt=0)]
FREE = "$"  # the first character of a free parameter's name (module docstring)
# keys that do not change what an evaluation gives: a rerun may change them and continue
BUDGET_KEYS = ("max_generations", "max_evaluations")
# the layout of an evaluation's record (studies.calibration.calibration_search): part of the hash, so that
# a checkpoint of another layout is refused, not misread
RECORD_LAYOUT = 2


class Parameter(StrictSpec):
    """One fitted scene value: its bounds, how the search scales them, and the physical reason."""

    scale: Literal["linear", "log"] = "linear"
    bounds: tuple[float, float] = Field(strict=False)  # a YAML list; its numbers stay strict
    reason: str = Field(min_length=1)

    @field_validator("bounds")
    @classmethod
    def _ordered(cls, bounds: tuple[float, float], info: ValidationInfo) -> tuple[float, float]:
        lower, upper = bounds
        if not lower < upper:
            raise ValueError(f"{list(bounds)}: the lower bound must be below the upper bound")
        if not math.isfinite(upper - lower):
            raise ValueError(f"{list(bounds)}: the bounds span more than a float holds")
        if info.data.get("scale") == "log" and lower <= 0:
            raise ValueError(f"{list(bounds)}: scale log needs a positive lower bound")
        return bounds

    def value(self, unit: float) -> float:
        """The value at unit coordinate u: lo + u (hi - lo), or lo (hi/lo)^u; clipped to the bounds."""
        lower, upper = self.bounds
        raw = lower * (upper / lower) ** unit if self.scale == "log" else lower + unit * (upper - lower)
        return float(np.clip(raw, lower, upper))

    def unit(self, value: float) -> float:
        """The unit coordinate of a value (inverse of :meth:`value`), clipped to [0, 1]."""
        lower, upper = self.bounds
        raw = math.log(value / lower) / math.log(upper / lower) if self.scale == "log" and value > 0 \
            else (value - lower) / (upper - lower)
        return float(np.clip(raw, 0.0, 1.0))


class Target(Scan):
    """A scan (studies.scan.curves) and where the paper puts its optimum."""

    optimum_hz: PositiveFloat
    band_hz: tuple[PositiveFloat, PositiveFloat] | None = Field(None, strict=False)  # as Parameter.bounds
    weight: PositiveFloat = 1.0
    tolerance: PositiveFloat = 0.15

    @model_validator(mode="after")
    def _band_around_optimum(self) -> Target:
        if self.band_hz is not None and not self.band_hz[0] <= self.optimum_hz <= self.band_hz[1]:
            raise ValueError(f"band_hz {list(self.band_hz)} must contain optimum_hz {self.optimum_hz} "
                             "(lower <= optimum <= upper)")
        return self


class SearchSettings(StrictSpec):
    """How the objective is minimised over the unit cube."""

    method: Literal["differential-evolution", "nelder-mead"] = "differential-evolution"
    popsize: int = Field(8, ge=1, le=MAX_NUM, description="DE: population = popsize x number of parameters")
    max_generations: int = Field(15, ge=0, le=MAX_NUM, description="DE: generations after the initial population")
    seed: int = Field(1, ge=0, le=2**63 - 1)
    max_evaluations: int = Field(100, ge=1, le=MAX_NUM, description="Nelder-Mead: evaluation budget")

    @model_validator(mode="after")
    def _keys_of_method(self) -> SearchSettings:
        own = {"differential-evolution": {"popsize", "max_generations", "seed"},
               "nelder-mead": {"max_evaluations"}}[self.method]
        foreign = sorted(self.model_fields_set - own - {"method"})
        if foreign:
            raise ValueError(f"{', '.join(foreign)}: not a setting of method {self.method!r}; "
                             f"its settings: {', '.join(sorted(own))}")
        return self

    @property
    def population(self) -> int:
        return 1 if self.method == "nelder-mead" else self.popsize

    def evaluations(self, parameters: int) -> int:
        """The search's budget in evaluations (DE: a population of popsize x n, at least 5, per
        generation and for the initial population)."""
        if self.method == "nelder-mead":
            return self.max_evaluations
        return max(5, self.popsize * parameters) * (self.max_generations + 1)


class CalibrationSpec(SceneSpec):
    """The calibration file as written (module docstring)."""

    frequency_hz: Axis
    refine_hz: PositiveFloat | None = None
    metric: MetricName = "penetration_rate_m_per_s"
    parameters: dict[str, Parameter] = Field(min_length=1)
    targets: list[Target] = Field(min_length=1)
    rising: list[Annotated[list[str], Field(min_length=2)]] = Field(default_factory=list)
    rising_weight: Annotated[float, Field(ge=0)] = 1.0
    search: SearchSettings = SearchSettings()


@dataclasses.dataclass(frozen=True)
class Calibration:
    """A validated calibration: the base scene (overrides set), scan frequencies and target labels."""

    source: Path
    spec: CalibrationSpec
    base: Scene
    frequencies_hz: tuple[float, ...]
    labels: tuple[str, ...]
    cpu_s: float = 0.0  # estimated for the whole calibration (models.solvers.cost)

    @property
    def names(self) -> list[str]:
        return list(self.spec.parameters)

    @property
    def evaluations(self) -> int:
        """The search's budget in evaluations (SearchSettings.evaluations)."""
        return self.spec.search.evaluations(len(self.spec.parameters))

    def metric(self, index: int) -> str:
        return self.spec.targets[index].metric or self.spec.metric

    def values(self, unit: np.ndarray) -> dict[str, float]:
        """Parameter values at a point of the unit cube."""
        return {name: parameter.value(float(u))
                for (name, parameter), u in zip(self.spec.parameters.items(), unit, strict=True)}

    def changes(self, values: dict[str, float], target: int | None = None) -> dict[str, Any]:
        """The scene changes of parameter values, then of a target's overrides (a free parameter's name
        given as a value replaced by its value), in that order."""
        overrides = resolve_free(self.spec.targets[target].overrides, values) if target is not None else {}
        scene_values = {path: value for path, value in values.items() if not is_free(path) and path not in overrides}
        return {**scene_values, **overrides}

    def scene(self, values: dict[str, float], target: int | None = None) -> Scene:
        """The base scene with parameter values and a target's overrides (:meth:`changes`)."""
        return self.base.with_(self.changes(values, target), f"{self.source} (parameters {values})")

    def start_unit(self) -> np.ndarray:
        """The base scene's values in unit coordinates (0.5 where the base scene has none: a free
        parameter, an optional key left out)."""
        values = {name: None if is_free(name) else scene_value(self.base, name) for name in self.spec.parameters}
        return np.array([0.5 if values[name] is None else parameter.unit(values[name])
                         for name, parameter in self.spec.parameters.items()])

    @property
    def identity(self) -> dict[str, str]:
        """What names this calibration in its checkpoint (studies.runtime.evaluation_log)."""
        return {"calibration": self.spec.name, "calibration_file": str(self.source), "hash": self.hash}

    @property
    def hash(self) -> str:
        """SHA-256 of what determines the evaluations and the search path: everything but the
        name, description, report refinement and budget (a larger budget continues a search)."""
        spec = self.spec.model_dump(mode="json", by_alias=True,
                                    exclude={"name", "description", "refine_hz", "base_scene", "base_overrides"})
        for key in BUDGET_KEYS:
            spec["search"].pop(key)
        content = {"spec": spec, "base_scene": self.base.model_dump(mode="json", by_alias=True),
                   "frequencies_hz": list(self.frequencies_hz), "labels": list(self.labels),
                   "record_layout": RECORD_LAYOUT}
        return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()


def is_free(name: str) -> bool:
    """Whether a parameter name is a free parameter (no scene key; module docstring)."""
    return name.startswith(FREE)


def _free_references(value: Any) -> list[str]:
    """The free parameter names a target override value gives (strings starting with ``$``, nested)."""
    if isinstance(value, str):
        return [value] if is_free(value) else []
    if isinstance(value, dict):
        return [name for item in value.values() for name in _free_references(item)]
    if isinstance(value, list):
        return [name for item in value for name in _free_references(item)]
    return []


def resolve_free(value: Any, values: dict[str, float]) -> Any:
    """``value`` with every free parameter name in it (nested in dicts and lists) replaced by its value."""
    if isinstance(value, str) and is_free(value):
        return values[value]
    if isinstance(value, dict):
        return {key: resolve_free(item, values) for key, item in value.items()}
    if isinstance(value, list):
        return [resolve_free(item, values) for item in value]
    return value


def _takes_numbers(annotation: Any) -> bool:
    """Whether a scene field's annotation is a real number (``float``, perhaps constrained or optional)."""
    if get_origin(annotation) is Annotated:
        return _takes_numbers(get_args(annotation)[0])
    if get_origin(annotation) in (Union, UnionType):
        kinds = [a for a in get_args(annotation) if a is not type(None)]
        return bool(kinds) and all(_takes_numbers(a) for a in kinds)
    return annotation is float


def _labels(spec: CalibrationSpec, source: str) -> tuple[str, ...]:
    labels = tuple(target.label or f"target {i}" for i, target in enumerate(spec.targets))
    for i, label in enumerate(labels):
        if labels.index(label) != i:
            raise InputError(f"{source}: targets.{i}.label: {label!r}: already the label of "
                             f"targets.{labels.index(label)}; labels must be unique")
    for i, chain in enumerate(spec.rising):
        for j, label in enumerate(chain):
            if label not in labels:
                raise InputError(f"{source}: rising.{i}.{j}: {label!r}: not a target label; labels: "
                                 f"{', '.join(labels)}")
            if chain.index(label) != j:
                raise InputError(f"{source}: rising.{i}.{j}: {label!r}: already in this order; each label once")
    return labels


def _check_scene(calibration: Calibration, key: str, values: dict[str, float], target: int, frequency_hz: float,
                 where: str, budget: Budget) -> float:
    """The estimated CPU seconds of a run of a target's scene at parameter ``values`` and a frequency;
    InputError unless it validates and prepares (its formulation able to run it), BudgetError beyond the
    budget of a run."""
    source = str(calibration.source)
    changes = {**calibration.changes(values, target), FREQUENCY: frequency_hz,
               "outputs": {"metrics": [calibration.metric(target)]}}
    try:
        simulation = prepare_point(calibration.base, {}, source, changes)
    except InputError as error:
        first = str(error).splitlines()[0].removeprefix(f"{source}: ")
        raise InputError(f"{source}: {key}: {where} is not a valid scene: {first}") from None
    return budget.check_run(simulation, source, f"{key}: {where}: ").cpu_s


def _check_scenes(calibration: Calibration, budget: Budget) -> float:
    """Every target at both ends of the scan must be a valid scene within the run budget at the start
    values and with each parameter at each bound (the others at their start values); the mean
    estimated CPU seconds of a run at the start values."""
    spec = calibration.spec
    start = calibration.values(calibration.start_unit())
    ends = (calibration.frequencies_hz[0], calibration.frequencies_hz[-1])
    cases = [("targets.{i}.overrides", start, "")] + [
        (f"parameters.{name}.bounds", start | {name: bound}, f" with {name} = {bound:g} ({side} bound)")
        for name, parameter in spec.parameters.items() for side, bound in zip(("lower", "upper"), parameter.bounds)]
    cpu = [[_check_scene(calibration, key.format(i=i), values, i, frequency, f"target {label!r} at {frequency:g} Hz{note}",
                         budget)
            for i, label in enumerate(calibration.labels) for frequency in ends] for key, values, note in cases]
    return float(np.mean(cpu[0]))


def _check_parameters(spec: CalibrationSpec, base: Scene, source: str) -> None:
    """A parameter names a scene key that takes a number, or is a free parameter that some target's
    overrides use; a target's overrides name scene keys and only declared free parameters."""
    used = {name for target in spec.targets for name in _free_references(target.overrides)}
    for name in spec.parameters:
        if is_free(name):
            if not name[1:].isidentifier():
                raise InputError(f"{source}: parameters.{name}: a free parameter is {FREE} and a name "
                                 "(letters, digits, underscores)")
            if name not in used:
                raise InputError(f"{source}: parameters.{name}: a free parameter no target's overrides use, "
                                 "so no scan depends on it; give it as an override value "
                                 f"(e.g. {{impact.amplitude_n: {name}}}) or drop it")
            continue
        check_scene_path(source, "parameters", name, base)
        field = field_at(Scene, tuple(name.split(".")))  # None: a parameter of one's own (an extension's)
        value = scene_value(base, name)
        numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not (numeric if field is None else _takes_numbers(field.annotation)):
            raise InputError(f"{source}: parameters.{name}: {value!r} in the base scene: a scene key "
                             "that does not take a real number; a fitted parameter is a key that does")
        if name == FREQUENCY or all(name in target.overrides for target in spec.targets):
            raise InputError(f"{source}: parameters.{name}: every target sets it (the scanned frequency or "
                             "its overrides), so no scan depends on it; fit a key the targets leave free")
    for i, target in enumerate(spec.targets):
        for key, value in target.overrides.items():
            check_scene_path(source, f"targets.{i}.overrides", key, base)
            for name in _free_references(value):
                if name not in spec.parameters:
                    raise InputError(f"{source}: targets.{i}.overrides.{key}: {name!r}: not a parameter; "
                                     f"free parameters: {', '.join(p for p in spec.parameters if is_free(p)) or 'none'}")


def _check_frequencies(spec: CalibrationSpec, frequencies: list[Any], source: str) -> None:
    """At least 3 increasing positive frequencies, every target's optimum and band inside the scan."""
    if len(frequencies) < 3 or any(not isinstance(f, (int, float)) or f <= 0 for f in frequencies) \
            or any(b <= a for a, b in itertools.pairwise(frequencies)):
        raise InputError(f"{source}: frequency_hz: {frequencies}: need at least 3 increasing positive frequencies")
    for i, target in enumerate(spec.targets):
        for key, values in (("optimum_hz", [target.optimum_hz]), ("band_hz", target.band_hz or [])):
            if any(not frequencies[0] <= f <= frequencies[-1] for f in values):
                raise InputError(f"{source}: targets.{i}.{key}: {values if key == 'band_hz' else values[0]}: outside "
                                 f"the scanned frequency_hz {frequencies[0]:g} .. {frequencies[-1]:g} Hz")


def scans_per_evaluation(spec: CalibrationSpec) -> int:
    """The distinct scans of an evaluation: targets with the same overrides and metric share one."""
    return len({json.dumps([t.overrides, t.metric or spec.metric], sort_keys=True) for t in spec.targets})


def load_calibration(path: str | Path, budget: Budget = DEFAULT_BUDGET, allow_code: Sequence[str] | str = ()) -> Calibration:
    """Read and validate a calibration file (``allow_code``: the modules of one's own its scenes may run), its
    runs checked against the ``budget``; InputError naming
    the file, key path and value, BudgetError naming the cost, otherwise."""
    path = Path(shipped_path(path, "calibration", "rpdrill.load_calibration"))
    source = str(path)
    spec = parse(CalibrationSpec, read_yaml(path), source)
    base = spec.base(path, allow_code)
    _check_parameters(spec, base, source)
    evaluations = spec.search.evaluations(len(spec.parameters))
    scans, count = scans_per_evaluation(spec), spec.frequency_hz.count
    what = (f"search: {evaluations:.6g} evaluations (search.popsize, search.max_generations, search.max_evaluations) "
            f"x {scans} scans x frequency_hz: {count:.6g} frequencies")
    runs = evaluations * scans * count
    metrics = {target.metric or spec.metric for target in spec.targets}
    budget.check_total(source, what, runs, runs * base_estimate_s(source, base, {"outputs": {"metrics": sorted(metrics)}}),
                       evaluations * EVALUATION_BYTES + count * AXIS_VALUE_BYTES)
    frequencies = spec.frequency_hz.expand()
    _check_frequencies(spec, frequencies, source)
    calibration = Calibration(path, spec, base, tuple(float(f) for f in frequencies), _labels(spec, source))
    run_s = _check_scenes(calibration, budget)
    spacing = max(b - a for a, b in itertools.pairwise(frequencies))
    report = len(spec.targets) * (count + (4 * spacing / spec.refine_hz + 2 if spec.refine_hz else 0))
    runs += report
    budget.check_total(source, f"{what} + refine_hz: {report:.6g} runs of the report", runs, runs * run_s)
    return dataclasses.replace(calibration, cpu_s=runs * run_s)
