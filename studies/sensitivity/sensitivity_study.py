"""Sensitivity of the frequency optima to the scene's parameters (the paper's section 3.3).

A sensitivity file names a base scene with overrides (studies.inputs.specs), the ``frequency_hz`` axis, the
labelled ``scans`` (studies.scan.frequency_scans.Scan), the ``rising`` trends, the ``metrics`` reported (default:
each scan's metric) and

* one at a time: every numeric value of the scene's drill string, feed, impact (not the scanned
  frequency), rock and extensions' parameters (``parameters: all``), or a listed set of dotted paths, each
  multiplied by
  1 +- ``relative_step`` (0.10) in every scan, after the scan's own overrides (a scan that sets the
  rock still has its rock stiffness changed);
* optionally ``global``: SALib's Morris screening (``method: morris``, ``samples`` trajectories) or
  Sobol indices (``method: sobol``, ``samples`` base samples, Saltelli's scheme) of ``parameters``,
  each factor uniform in 1 +- ``relative_span``.

Each point (a variation of one scan) is a scan of every frequency on the runner; its result is, per
metric, the main-lobe optimum frequency and the peak value there (studies.scan.frequency_scans). A variation keeps
the trends when every scan still has an optimum and every rising list still rises. Points run
through the resumable loop (studies.runtime.resumable): an interrupted study continues.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from ...models.definition.scene import Scene
from ..inputs.reading import InputError, parse, read_yaml
from ..inputs.specs import MAX_NUM, Axis, MetricName, SceneSpec, StrictSpec, check_scene_path, set_path
from ..runtime.budgets import DEFAULT_BUDGET, Budget, base_estimate_s
from ..runtime.resumable import cell
from ..scan.frequency_scans import (
    FREQUENCY,
    Scan,
    rising_shortfalls,
    scan_optimum,
    scan_scene,
    scan_target,
    set_frequency,
)

SECTIONS = ("drill_string", "feed", "impact", "rock", "extensions")
NOT_VARIED = (FREQUENCY, "segments")  # the scanned axis and counts
NOMINAL = "nominal"
ONE_AT_A_TIME_COLUMNS = ("parameter", "change", "scan", "metric", "optimum_hz", "optimum_change", "peak", "peak_change")
TREND_COLUMNS = ("parameter", "change", "every_scan_has_an_optimum", "rising_kept", "shortfalls")
Row = dict[str, str]


class GlobalAnalysis(StrictSpec):
    """A variance-based analysis with SALib over ``parameters``, each factor uniform in 1 +- span."""

    method: Literal["morris", "sobol"] = "morris"
    parameters: list[str] = Field(min_length=2)
    relative_span: float = Field(0.1, gt=0, lt=1)
    samples: int = Field(8, ge=2, le=MAX_NUM, description="Morris: trajectories; Sobol: base samples (a power of 2)")
    seed: int = 1


class SensitivitySpec(SceneSpec):
    """The sensitivity file as written (module docstring)."""

    frequency_hz: Axis
    metric: MetricName = "penetration_rate_m_per_s"
    metrics: list[MetricName] = Field(default_factory=list)
    scans: list[Scan] = Field(min_length=1)
    rising: list[list[str]] = Field(default_factory=list)
    parameters: Literal["all"] | list[str] = "all"
    relative_step: float = Field(0.1, gt=0, lt=1)
    global_analysis: GlobalAnalysis | None = Field(None, alias="global")

    def reported_metrics(self) -> list[str]:
        """The listed metrics, or every scan's metric."""
        return self.metrics or list(dict.fromkeys(scan.metric or self.metric for scan in self.scans))

    @model_validator(mode="after")
    def _labelled(self) -> SensitivitySpec:
        labels = [scan.label for scan in self.scans]
        if None in labels or len(set(labels)) < len(labels):
            raise ValueError("every scan needs a label, and labels must be unique")
        unknown = [label for chain in self.rising for label in chain if label not in labels]
        if unknown:
            raise ValueError(f"rising names {', '.join(map(repr, unknown))}: not a scan label; labels: {', '.join(labels)}")
        return self


@dataclass(frozen=True)
class SensitivityPoint:
    """One variation of one scan: ``parameters`` for the results table, the scan, and its scene (the base
    with the scan's overrides and the variation's factors)."""

    index: int
    parameters: dict[str, Any]
    scan: int
    scene: dict[str, Any]
    cpu_s: float  # estimated: the scan's frequencies, each a run of the base scene with its overrides


@dataclass(frozen=True)
class SensitivityStudy:
    """A validated sensitivity study: its points and what they scan."""

    source: Path
    spec: SensitivitySpec
    base: dict[str, Any]
    frequencies_hz: list[float]
    varied: list[str]  # the one-at-a-time parameters
    samples: np.ndarray | None  # global analysis: factors (rows) of its parameters
    points: list[SensitivityPoint]

    @property
    def labels(self) -> list[str]:
        return [scan.label for scan in self.spec.scans]

    def metrics(self) -> list[str]:
        """Reported metrics: the listed ones, or every scan's metric."""
        return self.spec.reported_metrics()

    def resolved(self) -> dict[str, Any]:
        return {**self.spec.model_dump(mode="json", by_alias=True), "base_scene": self.base,
                "varied": self.varied, "frequencies_hz": self.frequencies_hz}

    @property
    def hash(self) -> str:
        content = {"points": [[p.parameters, p.scene] for p in self.points],
                   "metrics": self.metrics(), "frequencies_hz": self.frequencies_hz}
        return hashlib.sha256(json.dumps(content, sort_keys=True, default=float).encode()).hexdigest()


def varied_scene(base: dict[str, Any], overrides: dict[str, Any], factors: dict[str, float]) -> dict[str, Any]:
    """The base scene with a scan's overrides, then every varied value multiplied by its factor."""
    scene = copy.deepcopy(base)
    for path, value in overrides.items():
        set_path(scene, path, value)
    values = scene_values(scene) if factors else {}
    for path, factor in factors.items():
        set_path(scene, path, values[path] * factor)
    return scene


def scene_values(scene_data: dict[str, Any]) -> dict[str, float]:
    """Every numeric value a scene sets in its drill string, feed, impact, rock (the rock's Table 1
    values filled in) and its extensions' parameters, by dotted path; values at their defaults are left out
    (nothing to vary)."""
    scene = Scene.model_validate(scene_data)
    data = scene.model_dump(mode="json", by_alias=True, exclude_defaults=True)
    data["rock"] = scene.rock.completed().model_dump(mode="json", exclude_defaults=True)
    values: dict[str, float] = {}

    def walk(node: Any, path: str) -> None:
        if isinstance(node, dict):
            for key, child in node.items():
                walk(child, f"{path}.{key}" if path else key)
        elif isinstance(node, (int, float)) and not isinstance(node, bool) and path.split(".")[-1] not in NOT_VARIED \
                and path != FREQUENCY:
            values[path] = float(node)

    walk({section: data[section] for section in SECTIONS if section in data}, "")
    return values


def _one_at_a_time(spec: SensitivitySpec, base: dict[str, Any], source: Path) -> list[str]:
    values = scene_values(base)
    if spec.parameters == "all":
        return [path for path, value in values.items() if value != 0.0]
    for path in spec.parameters:
        check_scene_path(str(source), "parameters", path, base)
        if path not in values:
            raise InputError(f"{source}: parameters: {path!r}: the base scene sets no number there; numbers: "
                             f"{', '.join(values)}")
    return list(spec.parameters)


def _global_samples(spec: GlobalAnalysis) -> np.ndarray:
    """SALib's sample of factors in 1 +- span (rows: samples, columns: parameters)."""
    from SALib.sample import morris, sobol

    problem = _problem(spec)
    if spec.method == "morris":
        return morris.sample(problem, spec.samples, num_levels=4, seed=spec.seed)
    return sobol.sample(problem, spec.samples, seed=spec.seed)


def _global_count(spec: GlobalAnalysis | None) -> int:
    """How many samples :func:`_global_samples` draws: Morris r (k + 1), Sobol (Saltelli) N (2 k + 2)."""
    if spec is None:
        return 0
    k = len(spec.parameters)
    return spec.samples * (k + 1 if spec.method == "morris" else 2 * k + 2)


def _problem(spec: GlobalAnalysis) -> dict[str, Any]:
    return {"num_vars": len(spec.parameters), "names": spec.parameters,
            "bounds": [[1 - spec.relative_span, 1 + spec.relative_span]] * len(spec.parameters)}


def load_sensitivity(path: str | Path, budget: Budget = DEFAULT_BUDGET) -> SensitivityStudy:
    """Read, validate and expand a sensitivity file; InputError naming the file and key otherwise,
    BudgetError when its runs together are beyond ``budget``."""
    path = Path(path)
    spec = parse(SensitivitySpec, read_yaml(path), str(path))
    base = spec.base_scene_dict(path)
    for i, scan in enumerate(spec.scans):
        for key in scan.overrides:
            check_scene_path(str(path), f"scans.{i}.overrides", key, base)
    varied = _one_at_a_time(spec, base, path)
    if spec.global_analysis is not None:
        for name in spec.global_analysis.parameters:
            if name not in scene_values(base):
                raise InputError(f"{path}: global.parameters: {name!r}: the base scene sets no number there")
    first_hz = spec.frequency_hz.start if spec.frequency_hz.values is None else spec.frequency_hz.values[0]
    metrics = spec.reported_metrics()
    scan_run_s = [base_estimate_s(str(path), scan_scene(varied_scene(base, scan.overrides, {}), first_hz, metrics))
                  for scan in spec.scans]
    count = 1 + 2 * len(varied) + _global_count(spec.global_analysis)
    budget.check_total(str(path), f"{count:.6g} variations x {len(spec.scans)} scans x frequency_hz: "
                       f"{spec.frequency_hz.count:.6g} values", count * len(spec.scans) * spec.frequency_hz.count,
                       count * spec.frequency_hz.count * sum(scan_run_s))
    frequencies = spec.frequency_hz.expand()
    variations: list[tuple[dict[str, Any], dict[str, float]]] = [({"kind": NOMINAL}, {})]
    variations += [({"kind": "one_at_a_time", "parameter": p, "change": f"{sign * spec.relative_step:+.3g}"},
                    {p: 1 + sign * spec.relative_step}) for p in varied for sign in (-1, 1)]
    samples = None
    if spec.global_analysis is not None:
        samples = _global_samples(spec.global_analysis)
        variations += [({"kind": "global", "sample": i}, dict(zip(spec.global_analysis.parameters, row.tolist())))
                       for i, row in enumerate(samples)]
    points = []
    for labels, factors in variations:
        for s, scan in enumerate(spec.scans):
            scene = varied_scene(base, scan.overrides, factors)
            parse(Scene, set_frequency(scene, frequencies[0]), f"{path} (scan {scan.label!r}, {labels})")
            points.append(SensitivityPoint(len(points), {**labels, "scan": scan.label}, s, scene,
                                len(frequencies) * scan_run_s[s]))
    return SensitivityStudy(path, spec, base, frequencies, varied, samples, points)


def columns(study: SensitivityStudy) -> list[str]:
    """The results table: point, variation, scan, status, then per metric its optimum and peak."""
    return ["point", "kind", "parameter", "change", "sample", "scan", "status", "error", "wall_time_s", "failed_runs",
            *[f"{m}:{q}" for m in study.metrics() for q in ("optimum_hz", "peak")]]


def task(study: SensitivityStudy, point: SensitivityPoint) -> tuple[Any, ...]:
    return point.index, point.scene, study.metrics(), study.frequencies_hz, study.labels[point.scan]


def run_variation(task_: tuple[Any, ...]) -> dict[str, Any]:
    """Worker: one point's scan and, per metric, its main-lobe optimum and peak (NaN without one); failed
    when every run of the scan failed."""
    index, scene, metrics, frequencies, label = task_
    start = time.perf_counter()
    scan = scan_target((index, scene, metrics, frequencies))
    results = {}
    for metric in metrics:
        optimum = scan_optimum(label, frequencies, scan, metric)
        results[f"{metric}:optimum_hz"] = math.nan if optimum["main_hz"] is None else optimum["main_hz"]
        results[f"{metric}:peak"] = optimum["main_value"]
    status = "failed" if scan["failed_runs"] == len(frequencies) else "ok"
    return {"point": index, "status": status, "error": scan["error"], "wall_time_s": time.perf_counter() - start,
            "metrics": {"failed_runs": scan["failed_runs"], **results}}


def row_of(study: SensitivityStudy, outcome: dict[str, Any]) -> dict[str, Any]:
    point = study.points[outcome["point"]]
    return {"point": point.index, "kind": "", "parameter": "", "change": "", "sample": "", **point.parameters,
            "status": outcome["status"], "error": outcome["error"], "wall_time_s": f"{outcome['wall_time_s']:.4g}",
            **{k: cell(f"{v:.10g}" if isinstance(v, float) else v) for k, v in outcome["metrics"].items()}}


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def _relative(value: float, nominal: float) -> float:
    return (value - nominal) / nominal if nominal and math.isfinite(nominal) else math.nan


def one_at_a_time(study: SensitivityStudy, rows: list[Row]) -> list[dict[str, Any]]:
    """Per varied parameter, change, scan and metric: optimum and peak, and their changes relative to
    the nominal scan."""
    nominal = {r["scan"]: r for r in rows if r["kind"] == NOMINAL}
    out = []
    for r in (r for r in rows if r["kind"] == "one_at_a_time"):
        for metric in study.metrics():
            base = nominal[r["scan"]]
            f, f0 = _number(r[f"{metric}:optimum_hz"]), _number(base[f"{metric}:optimum_hz"])
            p, p0 = _number(r[f"{metric}:peak"]), _number(base[f"{metric}:peak"])
            out.append({"parameter": r["parameter"], "change": float(r["change"]), "scan": r["scan"], "metric": metric,
                        "optimum_hz": f, "optimum_change": _relative(f, f0), "peak": p, "peak_change": _relative(p, p0)})
    return out


def trends(study: SensitivityStudy, rows: list[Row]) -> list[dict[str, Any]]:
    """Per variation (nominal and one at a time): whether every scan has an optimum of its metric and
    every rising list rises, with the shortfalls."""
    groups: dict[tuple[str, str], dict[str, Row]] = {}
    for r in rows:
        if r["kind"] in (NOMINAL, "one_at_a_time"):
            groups.setdefault((r["parameter"], r["change"]), {})[r["scan"]] = r
    out = []
    metric_of = {scan.label: scan.metric or study.spec.metric for scan in study.spec.scans}
    for (parameter, change), by_scan in groups.items():
        optima = {label: _number(by_scan[label][f"{metric_of[label]}:optimum_hz"]) for label in by_scan}
        optima = {label: None if math.isnan(f) else f for label, f in optima.items()}
        shortfalls = rising_shortfalls(study.spec.rising, optima)
        out.append({"parameter": parameter or NOMINAL, "change": change, "every_scan_has_an_optimum":
                    all(f is not None for f in optima.values()), "rising_kept": not shortfalls,
                    "shortfalls": [f"{a} >= {b} by {d:.3g} Hz" for a, b, d in shortfalls]})
    return out


def global_indices(study: SensitivityStudy, rows: list[Row]) -> list[dict[str, Any]]:
    """SALib indices per scan, metric and quantity (optimum frequency, peak); a sample without an optimum
    takes the nominal value (counted in ``missing``); where the nominal scan has none either, the indices
    are NaN (not computed)."""
    analysis = study.spec.global_analysis
    if analysis is None:
        return []
    from SALib.analyze import morris, sobol

    problem = _problem(analysis)
    nominal = {r["scan"]: r for r in rows if r["kind"] == NOMINAL}
    out = []
    for label in study.labels:
        samples = sorted((r for r in rows if r["kind"] == "global" and r["scan"] == label), key=lambda r: int(r["sample"]))
        for metric in study.metrics():
            for quantity in ("optimum_hz", "peak"):
                column = f"{metric}:{quantity}"
                values = np.array([_number(r[column]) for r in samples])
                missing = int(np.sum(~np.isfinite(values)))
                values[~np.isfinite(values)] = _number(nominal[label][column])
                names = ("mu_star", "sigma") if analysis.method == "morris" else ("S1", "ST")
                if not np.isfinite(values).all():
                    found = {k: np.full(len(analysis.parameters), np.nan) for k in names}
                elif analysis.method == "morris":
                    found = morris.analyze(problem, study.samples, values, num_levels=4, seed=analysis.seed)
                else:
                    found = sobol.analyze(problem, values, seed=analysis.seed)
                indices = {k: found[k] for k in names}
                for i, name in enumerate(analysis.parameters):
                    out.append({"scan": label, "metric": metric, "quantity": quantity, "parameter": name,
                                "missing": missing, **{k: float(v[i]) for k, v in indices.items()}})
    return out


def summary(study: SensitivityStudy, changes: list[dict[str, Any]], kept: list[dict[str, Any]]) -> dict[str, Any]:
    """The paper's 3.3 claim measured: the largest optimum shift and peak change of any +-step variation,
    per metric and overall, the parameters by their largest peak change, and how many variations keep
    the trends."""
    per_metric = {}
    for metric in study.metrics():
        mine = [c for c in changes if c["metric"] == metric]
        shifts = [abs(c["optimum_change"]) for c in mine if math.isfinite(c["optimum_change"])]
        peaks = [abs(c["peak_change"]) for c in mine if math.isfinite(c["peak_change"])]
        ranking: dict[str, float] = {}
        for c in mine:
            if math.isfinite(c["peak_change"]):
                ranking[c["parameter"]] = max(ranking.get(c["parameter"], 0.0), abs(c["peak_change"]))
        per_metric[metric] = {"largest_optimum_shift": max(shifts, default=math.nan),
                              "largest_peak_change": max(peaks, default=math.nan),
                              "median_peak_change": float(np.median(peaks)) if peaks else math.nan,
                              "parameters_by_peak_change": dict(sorted(ranking.items(), key=lambda kv: -kv[1]))}
    varied = [k for k in kept if k["parameter"] != NOMINAL]
    return {"relative_step": study.spec.relative_step, "metrics": per_metric,
            "variations": len(varied), "variations_keeping_every_trend":
                sum(k["every_scan_has_an_optimum"] and k["rising_kept"] for k in varied),
            "nominal_keeps_every_trend": all(k["every_scan_has_an_optimum"] and k["rising_kept"]
                                             for k in kept if k["parameter"] == NOMINAL)}
