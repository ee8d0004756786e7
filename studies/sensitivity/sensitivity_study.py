"""Sensitivity of the frequency optima to the scene's parameters (the paper's section 3.3).

A sensitivity file names a base scene with overrides (studies.inputs.specs), the ``frequency_hz`` axis, the
labelled ``scans`` (studies.scan.curves.Scan), the ``rising`` trends, the ``metrics`` reported (default:
each scan's metric) and

* one at a time: every numeric value of the scene's drill string, feed, impact (not the scanned
  frequency), rock and extensions' parameters (``parameters: all``), or a listed set of dotted paths, each
  multiplied by
  1 +- ``relative_step`` (0.10) in every scan, after the scan's own overrides (a scan that sets the
  rock still has its rock stiffness changed);
* optionally ``global``: SALib's Morris screening (``method: morris``, ``samples`` trajectories) or
  Sobol indices (``method: sobol``, ``samples`` base samples, Saltelli's scheme) of ``parameters``,
  each factor uniform in 1 +- ``relative_span``.

Each point (a variation of one scan: a typed scene, the base with the scan's overrides and the
variation's values) is a scan of every frequency on the runner (studies.scan.curves); its result is, per
metric, the main-lobe optimum frequency and the peak value there (studies.scan.curve_optima.Optimum). A
variation keeps the trends when every scan still has an optimum and every rising list still rises.
Points run through the resumable loop (studies.runtime.resumable): an interrupted study continues.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from ...models.definition.scene import Scene
from ..inputs.reading import InputError, parse, read_yaml
from ..inputs.shipped import shipped_path
from ..inputs.specs import MAX_NUM, Axis, MetricName, SceneSpec, StrictSpec, check_scene_path
from ..runtime.budgets import DEFAULT_BUDGET, Budget, base_estimate_s
from ..runtime.point_runs import point_scene
from ..scan.curve_optima import FREQUENCY
from ..scan.curves import Curve, Scan, rising_shortfalls, run_curve

if TYPE_CHECKING:
    import pandas as pd

SECTIONS = ("drill_string", "feed", "impact", "rock", "extensions")
NOT_VARIED = (FREQUENCY, "segments")  # the scanned axis and counts
NOMINAL = "nominal"
CHANGE_FORMAT = "+.3g"  # a variation's relative change as the tables write it
ONE_AT_A_TIME_COLUMNS = ("parameter", "change", "scan", "metric", "optimum_hz", "optimum_change", "peak", "peak_change")
TREND_COLUMNS = ("parameter", "change", "every_scan_has_an_optimum", "rising_kept", "shortfalls")
VARIATION_COLUMNS = ("kind", "parameter", "change", "sample", "scan")  # a row's start: which variation of which scan
TEXT_COLUMNS = ("kind", "parameter", "scan")  # text even where empty (a change and a sample are numbers)


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
    """One variation of one scan: ``values`` for the results table (VARIATION_COLUMNS: its kind, the
    parameter and relative change or the global sample, the scan's label), the scan, and its scene (the
    base with the scan's overrides and the variation's values, at the first frequency)."""

    index: int
    values: dict[str, Any]
    scan: int
    scene: Scene
    cpu_s: float  # estimated: the scan's frequencies, each a run of the base scene with its overrides


@dataclass(frozen=True)
class SensitivityStudy:
    """A validated sensitivity study: its points and what they scan."""

    source: Path
    spec: SensitivitySpec
    base: Scene
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
        return {**self.spec.model_dump(mode="json", by_alias=True),
                "base_scene": self.base.model_dump(mode="json", by_alias=True, exclude_none=True),
                "varied": self.varied, "frequencies_hz": self.frequencies_hz}

    @property
    def hash(self) -> str:
        content = {"points": [[p.values, p.scene.model_dump(mode="json", by_alias=True)] for p in self.points],
                   "metrics": self.metrics(), "frequencies_hz": self.frequencies_hz}
        return hashlib.sha256(json.dumps(content, sort_keys=True, default=float).encode()).hexdigest()


def varied_scene(base: Scene, overrides: dict[str, Any], factors: dict[str, float], frequency_hz: float,
                 source: str) -> Scene:
    """The base scene with a scan's overrides, then every varied value multiplied by its factor, at
    ``frequency_hz`` (InputError naming ``source`` when that is no valid scene)."""
    if not factors:
        return point_scene(base, {FREQUENCY: frequency_hz}, source, overrides)
    scene = base.with_(overrides, source)  # whose values the factors multiply
    values = scene_values(scene)
    return point_scene(scene, {FREQUENCY: frequency_hz}, source, {path: values[path] * factor
                                                                 for path, factor in factors.items()})


def scene_values(scene: Scene) -> dict[str, float]:
    """Every numeric value a scene sets in its drill string, feed, impact, rock (the rock's Table 1
    values filled in) and its extensions' parameters, by dotted path; values at their defaults are left out
    (nothing to vary)."""
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


def _one_at_a_time(spec: SensitivitySpec, base: Scene, source: Path) -> list[str]:
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


def load_sensitivity(path: str | Path, budget: Budget = DEFAULT_BUDGET, allow_code: Sequence[str] | str = ()) -> SensitivityStudy:
    """Read, validate and expand a sensitivity file (``allow_code``: the modules of one's own its scenes may
    run); InputError naming the file and key otherwise, BudgetError when its runs together are beyond ``budget``."""
    path = Path(shipped_path(path, "sensitivity", "rpdrill.load_sensitivity"))
    spec = parse(SensitivitySpec, read_yaml(path), str(path))
    base = spec.base(path, allow_code)
    for i, scan in enumerate(spec.scans):
        for key in scan.overrides:
            check_scene_path(str(path), f"scans.{i}.overrides", key, base)
    varied = _one_at_a_time(spec, base, path)
    if spec.global_analysis is not None:
        for name in spec.global_analysis.parameters:
            if name not in scene_values(base):
                raise InputError(f"{path}: global.parameters: {name!r}: the base scene sets no number there")
    first_hz = spec.frequency_hz.start if spec.frequency_hz.values is None else spec.frequency_hz.values[0]
    outputs = {"outputs": {"metrics": spec.reported_metrics()}}
    scan_run_s = [base_estimate_s(str(path), base, {**scan.overrides, FREQUENCY: first_hz, **outputs})
                  for scan in spec.scans]
    count = 1 + 2 * len(varied) + _global_count(spec.global_analysis)
    budget.check_total(str(path), f"{count:.6g} variations x {len(spec.scans)} scans x frequency_hz: "
                       f"{spec.frequency_hz.count:.6g} values", count * len(spec.scans) * spec.frequency_hz.count,
                       count * spec.frequency_hz.count * sum(scan_run_s))
    frequencies = spec.frequency_hz.expand()
    blank = dict.fromkeys(VARIATION_COLUMNS)
    variations: list[tuple[dict[str, Any], dict[str, float]]] = [({**blank, "kind": NOMINAL}, {})]
    variations += [({**blank, "kind": "one_at_a_time", "parameter": p, "change": sign * spec.relative_step},
                    {p: 1 + sign * spec.relative_step}) for p in varied for sign in (-1, 1)]
    samples = None
    if spec.global_analysis is not None:
        samples = _global_samples(spec.global_analysis)
        variations += [({**blank, "kind": "global", "sample": i}, dict(zip(spec.global_analysis.parameters,
                                                                           row.tolist())))
                       for i, row in enumerate(samples)]
    points = []
    for labels, factors in variations:
        for s, scan in enumerate(spec.scans):
            shown = {k: v if k != "change" else format(v, CHANGE_FORMAT) for k, v in labels.items() if v is not None}
            scene = varied_scene(base, scan.overrides, factors, frequencies[0], f"{path} (scan {scan.label!r}, {shown})")
            points.append(SensitivityPoint(len(points), {**labels, "scan": scan.label}, s, scene,
                                           len(frequencies) * scan_run_s[s]))
    return SensitivityStudy(path, spec, base, frequencies, varied, samples, points)


def columns(study: SensitivityStudy) -> list[str]:
    """The results table: point, variation, scan, status, then per metric its optimum and peak."""
    return ["point", *VARIATION_COLUMNS, "status", "error", "wall_time_s", "failed_runs", *quantity_columns(study)]


def quantity_columns(study: SensitivityStudy) -> list[str]:
    """Per reported metric, its optimum frequency and its peak (the main lobe's)."""
    return [f"{m}:{q}" for m in study.metrics() for q in ("optimum_hz", "peak")]


def curve(study: SensitivityStudy, point: SensitivityPoint) -> Curve:
    """What a point scans: its scene along the study's frequencies."""
    return Curve(point.index, point.scene, {}, tuple(study.frequencies_hz), tuple(study.metrics()))


def run_variation(scan: Curve) -> dict[str, Any]:
    """Worker: one point's scan and, per metric, its main-lobe optimum and peak (NaN and 0 without one);
    failed when every run of the scan failed."""
    start = time.perf_counter()
    run = run_curve(scan)
    results = {}
    for metric in scan.metrics:
        optimum = run.optimum(metric)
        results[f"{metric}:optimum_hz"] = math.nan if optimum.optimum is None else optimum.optimum
        results[f"{metric}:peak"] = optimum.optimum_value or 0.0
    status = "failed" if run.failed_runs == len(scan.values) else "ok"
    return {"status": status, "error": run.error, "wall_time_s": time.perf_counter() - start,
            "failed_runs": run.failed_runs, **results}


def number_formats(study: SensitivityStudy) -> dict[str, str]:
    """How the results table writes its numbers: a change as '+0.1', optima and peaks to 10 digits."""
    return {"change": CHANGE_FORMAT, **dict.fromkeys(quantity_columns(study), ".10g")}


def _relative(value: float, nominal: float) -> float:
    return (value - nominal) / nominal if nominal and math.isfinite(nominal) else math.nan


def one_at_a_time(study: SensitivityStudy, table: pd.DataFrame) -> pd.DataFrame:
    """Per varied parameter, change, scan and metric: optimum and peak, and their changes relative to
    the nominal scan (ONE_AT_A_TIME_COLUMNS)."""
    import pandas as pd

    nominal = {r["scan"]: r for r in table[table["kind"] == NOMINAL].to_dict("records")}
    out = []
    for r in table[table["kind"] == "one_at_a_time"].to_dict("records"):
        for metric in study.metrics():
            base = nominal[r["scan"]]
            f, f0 = r[f"{metric}:optimum_hz"], base[f"{metric}:optimum_hz"]
            p, p0 = r[f"{metric}:peak"], base[f"{metric}:peak"]
            out.append({"parameter": r["parameter"], "change": r["change"], "scan": r["scan"], "metric": metric,
                        "optimum_hz": f, "optimum_change": _relative(f, f0), "peak": p, "peak_change": _relative(p, p0)})
    return pd.DataFrame(out, columns=list(ONE_AT_A_TIME_COLUMNS))


def _change_text(change: float) -> str:
    return "" if math.isnan(change) else format(change, CHANGE_FORMAT)


def trends(study: SensitivityStudy, table: pd.DataFrame) -> pd.DataFrame:
    """Per variation (nominal and one at a time): whether every scan has an optimum of its metric and
    every rising list rises, with the shortfalls (TREND_COLUMNS)."""
    import pandas as pd

    groups: dict[tuple[str, str], dict[str, dict[str, Any]]] = {}
    for r in table[table["kind"].isin((NOMINAL, "one_at_a_time"))].to_dict("records"):
        groups.setdefault((r["parameter"], _change_text(r["change"])), {})[r["scan"]] = r
    out = []
    metric_of = {scan.label: scan.metric or study.spec.metric for scan in study.spec.scans}
    for (parameter, change), by_scan in groups.items():
        optima = {label: by_scan[label][f"{metric_of[label]}:optimum_hz"] for label in by_scan}
        optima = {label: None if math.isnan(f) else f for label, f in optima.items()}
        shortfalls = rising_shortfalls(study.spec.rising, optima)
        out.append({"parameter": parameter or NOMINAL, "change": change, "every_scan_has_an_optimum":
                    all(f is not None for f in optima.values()), "rising_kept": not shortfalls,
                    "shortfalls": "; ".join(f"{a} >= {b} by {d:.3g} Hz" for a, b, d in shortfalls)})
    return pd.DataFrame(out, columns=list(TREND_COLUMNS))


def global_indices(study: SensitivityStudy, table: pd.DataFrame) -> pd.DataFrame:
    """SALib indices per scan, metric and quantity (optimum frequency, peak); a sample without an optimum
    takes the nominal value (counted in ``missing``); where the nominal scan has none either, the indices
    are NaN (not computed). Empty without a global analysis."""
    import pandas as pd

    analysis = study.spec.global_analysis
    if analysis is None:
        return pd.DataFrame()
    from SALib.analyze import morris, sobol

    problem = _problem(analysis)
    nominal = {r["scan"]: r for r in table[table["kind"] == NOMINAL].to_dict("records")}
    out = []
    for label in study.labels:
        samples = table[(table["kind"] == "global") & (table["scan"] == label)].sort_values("sample", kind="stable")
        for metric in study.metrics():
            for quantity in ("optimum_hz", "peak"):
                column = f"{metric}:{quantity}"
                values = samples[column].to_numpy(dtype=float, copy=True)
                missing = int(np.sum(~np.isfinite(values)))
                values[~np.isfinite(values)] = nominal[label][column]
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
    return pd.DataFrame(out)


def summary(study: SensitivityStudy, changes_table: pd.DataFrame, kept_table: pd.DataFrame) -> dict[str, Any]:
    """The paper's 3.3 claim measured: the largest optimum shift and peak change of any +-step variation,
    per metric and overall, the parameters by their largest peak change, and how many variations keep
    the trends."""
    changes, kept = changes_table.to_dict("records"), kept_table.to_dict("records")
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
