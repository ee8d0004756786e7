"""The paper reproduced: each of its headline cases scanned on the shipped scene, the optima beside the
paper's, its trends checked, the lobes below the main resonance listed.

A reproduction file (``studies/paper/reproduction.yaml``) names the base scene with overrides
(studies.inputs.specs), the ``frequency_hz`` axis, the ``metrics`` recorded, the ``cases`` (studies.scan.curves
scans, each with what the ``paper`` says: ``optimum_hz``, ``band_hz`` and the words), the ``rising``
trends, the case whose lobes explain the sawtooth below the resonance (``sub_harmonics``) and the
``figures`` to redraw (cases and metrics of each). Every case's optimum is the maximum of its main
lobe (the lobe nearest to the rock-mode resonance of models.drill.modal), refined by the parabola through
the best point and its neighbours (studies.scan.curve_optima); the global maximum is given beside it, so that a
sub-harmonic lobe as high as the main one is never taken for it silently. ``variants`` repeat every case
on another drill (another upper string: bodies and connectors added, paths overridden), to show what
the result depends on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, model_validator

from ...models.definition.scene import Scene
from ..inputs.reading import InputError, parse, read_yaml
from ..inputs.shipped import shipped_path
from ..inputs.specs import Axis, MetricName, SceneSpec, StrictSpec, check_scene_path
from ..runtime.pools import Runner
from ..scan.curve_optima import Optimum
from ..scan.curves import Curve, Scan, rising_shortfalls, run_all

PositiveFloat = Field(gt=0, allow_inf_nan=False)


class PaperResult(StrictSpec):
    """What the paper reports for a case: its optimum (the centre of its band), its band, its words."""

    optimum_hz: float | None = Field(None, gt=0, allow_inf_nan=False)
    band_hz: tuple[float, float] | None = Field(None, strict=False)  # a YAML list; its numbers stay strict
    says: str


class Case(Scan):
    """A scan of the paper (studies.scan.curves.Scan) and what the paper says about it."""

    paper: PaperResult


class Figure(StrictSpec):
    """One of the paper's figures: the cases it shows and the metrics of its panels."""

    number: int
    title: str
    cases: list[str] = Field(min_length=1)
    metrics: list[MetricName] = Field(min_length=1)


class Variant(StrictSpec):
    """Another upper string (or any change of the drill): ``overrides`` of the base scene's paths, and
    bodies and connectors ``add``-ed under new names (``add: {bodies: {..}, connectors: {..}}``)."""

    label: str
    description: str
    overrides: dict[str, Any] = Field(default_factory=dict)
    add: dict[Literal["bodies", "connectors"], dict[str, Any]] = Field(default_factory=dict)


class ReproductionSpec(SceneSpec):
    """The reproduction file as written (module docstring)."""

    frequency_hz: Axis
    metric: MetricName = "penetration_rate_m_per_s"
    metrics: list[MetricName] = Field(min_length=1)
    tolerance: float = Field(0.15, gt=0)
    cases: list[Case] = Field(min_length=1)
    rising: list[list[str]] = Field(default_factory=list)
    sub_harmonics: str
    figures: list[Figure] = Field(default_factory=list)
    variants: list[Variant] = Field(default_factory=list)
    calibration: str | None = Field(None, description="the calibration file (relative to this file) whose bounds "
                                                      "and reasons the parameters page lists")

    @model_validator(mode="after")
    def _labels_refer_to_cases(self) -> ReproductionSpec:
        labels = [case.label for case in self.cases]
        if None in labels or len(set(labels)) < len(labels):
            raise ValueError("every case needs a label, and labels must be unique")
        named = [label for chain in self.rising for label in chain] + [self.sub_harmonics] + \
            [label for figure in self.figures for label in figure.cases]
        unknown = sorted({label for label in named if label not in labels})
        if unknown:
            raise ValueError(f"{', '.join(map(repr, unknown))}: not a case label; labels: {', '.join(labels)}")
        used = {case.metric or self.metric for case in self.cases} | {m for f in self.figures for m in f.metrics}
        missing = sorted(used - set(self.metrics))
        if missing:
            raise ValueError(f"metrics must list {', '.join(missing)} (used by a case or a figure)")
        return self


@dataclass(frozen=True)
class Reproduction:
    """A validated reproduction file."""

    source: Path
    spec: ReproductionSpec
    base: Scene
    frequencies_hz: list[float]

    @property
    def calibration_file(self) -> Path | None:
        return None if self.spec.calibration is None else self.source.parent / self.spec.calibration

    def metric(self, case: Case) -> str:
        return case.metric or self.spec.metric

    def changes(self, case: Case, variant: Variant | None = None) -> dict[str, Any]:
        """The scene changes of a case (on a variant): the variant's bodies and connectors added, its
        overrides, then the case's overrides (a path of both: the case's), in that order."""
        changes = variant_changes(self.base, variant)
        for path, value in case.overrides.items():
            changes.pop(path, None)
            changes[path] = value
        return changes

    def scene(self, case: Case, variant: Variant | None = None) -> Scene:
        """The case's scene at the base scene's frequency (:meth:`changes`)."""
        return self.base.with_(self.changes(case, variant), f"{self.source} (case {case.label!r})")


def variant_changes(base: Scene, variant: Variant | None) -> dict[str, Any]:
    """A variant's scene changes: the drill string's bodies and connectors with its own added, then its
    overrides."""
    if variant is None:
        return {}
    string = base.model_dump(by_alias=True, exclude_none=True)["drill_string"]
    added = {f"drill_string.{part}": {**string[part], **named} for part, named in variant.add.items()}
    return {**added, **variant.overrides}


@dataclass(frozen=True)
class CaseResult:
    """A case on the shipped scene: the curves of every metric, the optimum of its metric
    (studies.scan.curve_optima.Optimum: main lobe, global maximum, every lobe), its first failed run's error,
    and from which frequency on nothing is crushed (None if it crushes to the scan's end; only for a
    penetration metric)."""

    case: Case
    metric: str
    curves: dict[str, list[float]]
    optimum: Optimum
    error: str
    silent_from_hz: float | None


def load_reproduction(path: str | Path, allow_code: Sequence[str] | str = ()) -> Reproduction:
    """Read and validate a reproduction file (``allow_code``: the modules of one's own its scenes may run);
    InputError naming the file and key otherwise."""
    path = Path(shipped_path(path, "reproduction", "rpdrill.load_reproduction"))
    spec = parse(ReproductionSpec, read_yaml(path), str(path))
    base = spec.base(path, allow_code)
    for i, case in enumerate(spec.cases):
        for key in case.overrides:
            check_scene_path(str(path), f"cases.{i}.overrides", key, base)
    string = base.model_dump(by_alias=True, exclude_none=True)["drill_string"]
    for i, variant in enumerate(spec.variants):
        for part, named in variant.add.items():
            taken = sorted(set(named) & set(string[part]))
            if taken:
                raise InputError(f"{path}: variants.{i}.add.{part}: {', '.join(taken)}: already in the base scene; "
                                 "change it with overrides")
        added = {key: value for key, value in variant_changes(base, variant).items() if key not in variant.overrides}
        extended = base.with_(added, f"{path}: variants.{i}.add")
        for key in variant.overrides:
            check_scene_path(str(path), f"variants.{i}.overrides", key, extended)
    return Reproduction(path, spec, base, spec.frequency_hz.expand())


def _silent_from_hz(frequencies_hz: list[float], values: list[float], main_hz: float | None) -> float | None:
    """The lowest frequency above the main optimum from which the metric stays zero to the scan's end."""
    if main_hz is None:
        return None
    silent = None
    for frequency, value in zip(reversed(frequencies_hz), reversed(values), strict=True):
        if frequency <= main_hz or not (math.isfinite(value) and value <= 0.0):
            break
        silent = frequency
    return silent


def scan_cases(reproduction: Reproduction, runner: Runner) -> tuple[dict[str | None, list[CaseResult]], dict[str, Any]]:
    """Scan every case of the shipped scene (key None) and of every variant (key: its label), all on the
    runner at once: the results, and what the scans cost."""
    spec, frequencies = reproduction.spec, reproduction.frequencies_hz
    variants: list[Variant | None] = [None, *spec.variants]
    curves = [Curve((v, i), reproduction.base, reproduction.changes(case, variant), tuple(frequencies),
                    tuple(spec.metrics)) for v, variant in enumerate(variants) for i, case in enumerate(spec.cases)]
    runs, cost = run_all(runner, curves)
    return {None if variant is None else variant.label: _case_results(reproduction, [runs[(v, i)] for i in
                                                                                    range(len(spec.cases))])
            for v, variant in enumerate(variants)}, cost


def _case_results(reproduction: Reproduction, runs: list[Any]) -> list[CaseResult]:
    frequencies = reproduction.frequencies_hz
    results = []
    for case, run in zip(reproduction.spec.cases, runs, strict=True):
        metric = reproduction.metric(case)
        optimum = run.optimum(metric)
        curves = {name: run.values(name) for name in reproduction.spec.metrics}
        silent = _silent_from_hz(frequencies, curves[metric], optimum.optimum) \
            if metric in ("penetration_rate_m_per_s", "advance_per_blow_m") else None
        results.append(CaseResult(case, metric, curves, optimum, run.error, silent))
    return results


def within(value_hz: float | None, paper: PaperResult, tolerance: float) -> bool | None:
    """Whether an optimum lies within ``tolerance`` of the paper's (None where the paper gives none)."""
    if paper.optimum_hz is None:
        return None
    return value_hz is not None and abs(value_hz - paper.optimum_hz) <= tolerance * paper.optimum_hz


def trend_checks(reproduction: Reproduction, results: list[CaseResult]) -> list[dict[str, Any]]:
    """Per rising list: the main-lobe optima in order and whether they rise (the shortfalls if not)."""
    optima = {r.case.label: r.optimum.optimum for r in results}
    return [{"cases": chain, "optima_hz": [optima[label] for label in chain],
             "shortfalls": rising_shortfalls([chain], optima),
             "rises": all(optima[label] is not None for label in chain) and not rising_shortfalls([chain], optima)}
            for chain in reproduction.spec.rising]


def sub_harmonic_lobes(reproduction: Reproduction, results: list[CaseResult]) -> list[dict[str, Any]]:
    """The lobes of the ``sub_harmonics`` case, each with the rock-mode resonance f_r over its peak and the
    nearest whole number n: a lobe near f_r / n is driven in phase by every n-th blow."""
    result = next(r for r in results if r.case.label == reproduction.spec.sub_harmonics)
    resonance = result.optimum.resonance_hz
    lobes = []
    for lobe in result.optimum.lobes:
        ratio = resonance / lobe.peak if resonance else math.nan
        lobes.append({"peak_hz": lobe.peak, "peak_value": lobe.peak_value, "band_50_hz": lobe.band_50,
                      "resonance_over_peak": ratio, "nearest_n": round(ratio) if math.isfinite(ratio) else None,
                      "main": lobe is result.optimum.main_lobe})
    return lobes
