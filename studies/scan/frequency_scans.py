"""Labelled frequency scans of a base scene and their optima: what the calibration fits and the
sensitivity study varies.

A :class:`Scan` is the base scene with ``overrides`` scanned over impact frequency; its ``metric``'s
optimum is the maximum of its main lobe (studies.scan.curve_optima: the lobe nearest to the rock-mode
resonance of models.drill.modal, refined by the parabola through the best point and its neighbours),
reported beside the global maximum. Many scans (every scan of many parameter sets) go to a runner
together, one task per scan, each distinct scan once; ``rising`` lists of labels are trends the
optima must follow (the paper's 3.1 b: the optimum rises with the impulse).
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Iterator, Sequence
from typing import Any

from pydantic import Field

from ...models.drill.modal import rock_mode_frequency_hz
from ...models.steady.continuation import Continuation, branch_point
from ..inputs.reading import InputError
from ..inputs.specs import MetricName, StrictSpec
from ..runtime.point_runs import prepare_point, run_prepared
from ..runtime.pools import Runner
from .curve_optima import curve_optimum

FREQUENCY = "impact.frequency_hz"
# (key, scene dict, metrics, frequencies)
ScanTask = tuple[Any, dict[str, Any], list[str], list[float]]
Record = dict[str, Any]


class Scan(StrictSpec):
    """One frequency scan of the base scene with ``overrides``; its optimum is that of ``metric``
    (default: the file's ``metric``)."""

    label: str | None = None
    overrides: dict[str, Any] = Field(default_factory=dict)
    metric: MetricName | None = None


def set_frequency(scene: dict[str, Any], frequency_hz: float) -> dict[str, Any]:
    """``scene`` at ``frequency_hz``: a new mapping and ``impact`` section, the other sections shared with
    ``scene`` (nothing changes them: a point is validated into a new Scene), so that a scan of many points
    does not copy the whole scene for each."""
    return {**scene, "impact": {**scene.get("impact", {}), FREQUENCY.split(".")[1]: frequency_hz}}


def scan_scene(scene: dict[str, Any], frequency_hz: float, metrics: Sequence[str]) -> dict[str, Any]:
    """One point of a scan: ``scene`` at ``frequency_hz``, asked for ``metrics`` only (the model then
    records only what they need)."""
    return {**set_frequency(scene, frequency_hz), "outputs": {"metrics": list(metrics)}}


def scan_target(task: ScanTask) -> dict[str, Any]:
    """Worker: one scan, each metric at every frequency (NaN where a run failed; failures are counted,
    not raised), the scene's rock-mode frequency (None if it has none) and CPU seconds."""
    key, scene, metrics, frequencies = task
    start = time.process_time()
    values: dict[str, list[float]] = {metric: [] for metric in metrics}
    errors, resonance = [], None
    branch = Continuation()  # solver.steady_state periodic: each orbit from its neighbours' (models.steady)
    for frequency in frequencies:
        try:
            simulation = prepare_point("frequency scan", scan_scene(scene, frequency, metrics), {})
        except InputError as error:
            outcome = {"status": "failed", "error": str(error), "metrics": {}}
        else:
            resonance = resonance or rock_mode_frequency_hz(simulation.chain, simulation.rock) or None
            outcome, result = run_prepared(key, simulation, branch.guess(frequency), branch.cold_newton)
            if result is not None:
                branch.add(branch_point(frequency, result.info, math.nan))
        for metric in metrics:
            values[metric].append(outcome["metrics"].get(metric, math.nan))
        if outcome["status"] == "failed":  # (an unsettled or unstable run has its values: models.evaluation.run_status)
            errors.append(outcome["error"])
    return {"key": key, "values": values, "resonance_hz": resonance, "failed_runs": len(errors),
            "error": errors[0] if errors else "", "cpu_time_s": time.process_time() - start}


def run_scans(runner: Runner, tasks: list[ScanTask]) -> Iterator[tuple[list[Any], dict[str, Any]]]:
    """Run the scans on the runner, each distinct (scene, metrics, frequencies) once (two tasks may be
    the same scan); yields (the keys of the tasks it answers, scan) as scans end."""
    keys: dict[str, list[Any]] = {}
    first: dict[str, ScanTask] = {}
    for task in tasks:
        signature = json.dumps(task[1:], sort_keys=True)
        keys.setdefault(signature, []).append(task[0])
        first.setdefault(signature, task)
    served = {task[0]: keys[signature] for signature, task in first.items()}
    for batch in runner(scan_target, list(first.values())) if first else ():
        for scan in batch:
            yield served[scan["key"]], scan


def scan_all(runner: Runner, tasks: list[ScanTask]) -> tuple[dict[Any, dict[str, Any]], dict[str, Any]]:
    """Every task's scan by its key, and what the distinct scans cost (:func:`scan_cost`)."""
    scans, ran = {}, []
    for served, scan in run_scans(runner, tasks):
        scans.update(dict.fromkeys(served, scan))
        ran.append(scan)
    return scans, scan_cost(ran)


def scan_cost(scans: list[dict[str, Any]]) -> dict[str, Any]:
    """Simulations, failed runs and CPU seconds of distinct scans."""
    return {"simulations": sum(len(next(iter(scan["values"].values()))) for scan in scans),
            "failed_runs": sum(scan["failed_runs"] for scan in scans),
            "cpu_time_s": sum(scan["cpu_time_s"] for scan in scans)}


def scan_optimum(label: str, frequencies_hz: list[float], scan: dict[str, Any], metric: str) -> Record:
    """The optima of one metric of a scan: main lobe (refined frequency, peak value, bands) and global
    maximum (module doc)."""
    optimum = curve_optimum(frequencies_hz, scan["values"][metric], scan["resonance_hz"])
    main, highest = optimum.main_lobe, optimum.global_lobe
    return {
        "label": label, "metric": metric, "resonance_hz": scan["resonance_hz"],
        "main_hz": None if main is None else main.peak_hz, "main_value": 0.0 if main is None else main.peak_value,
        "main_at_scan_end": main is not None and main.peak_at_scan_end,
        "band_80_hz": None if main is None else list(main.band_80_hz),
        "band_50_hz": None if main is None else list(main.band_50_hz),
        "global_hz": None if highest is None else highest.peak_hz,
        "global_value": 0.0 if highest is None else highest.peak_value,
        "failed_runs": scan["failed_runs"], "error": scan["error"],
    }


def rising_shortfalls(rising: list[list[str]], optima_hz: dict[str, float | None]) -> list[tuple[str, str, float]]:
    """(a, b, f_a - f_b) for neighbouring labels of each rising list whose optima do not rise (pairs
    where a scan has no optimum are left out)."""
    return [(a, b, optima_hz[a] - optima_hz[b]) for chain in rising for a, b in itertools.pairwise(chain)
            if optima_hz[a] is not None and optima_hz[b] is not None and optima_hz[a] >= optima_hz[b]]
