"""What a calibration writes: the calibrated scene, the per-target table, the trade-off, the record.

* ``calibrated_scene.yaml``: the base scene (with its overrides) and the best parameter values;
* ``targets.csv`` and ``targets.md``: per target the paper's optimum and band, the reached
  main-lobe and global-maximum optima (scan of the best set, refined around its optima), the
  relative miss, whether it is within the target's tolerance, the peak value of the metric;
* ``pareto.csv``: the non-dominated evaluations over the per-target |misses| (no other evaluation
  misses every target by at most as much and one by less): the alternatives when the targets
  cannot all be met together, and what each gives up;
* ``best_curves.csv``: the best set's scans (target, frequency, metric value);
* ``calibration.json``: the spec, the best evaluation, every evaluation, the cost.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...models.evaluation.workprecision import non_dominated
from ..runtime.output_files import write_json, write_resolved, write_rows_csv
from ..runtime.tables import write_table
from .calibration_search import CalibrationEvaluation, SearchResult, TargetResult
from .calibration_spec import Calibration

if TYPE_CHECKING:
    import pandas as pd

TARGET_COLUMNS = ("label", "metric", "paper_optimum_hz", "paper_band_low_hz", "paper_band_high_hz",
                  "resonance_estimate_hz", "main_lobe_optimum_hz", "main_lobe_band_80_low_hz",
                  "main_lobe_band_80_high_hz", "global_max_optimum_hz", "relative_miss", "tolerance",
                  "within_tolerance", "main_lobe_peak_value", "global_max_peak_value", "failed_runs")


HEADER = ("| target | metric | paper [Hz] | reached, main lobe [Hz] (80 % band) | reached, global max [Hz] "
          "| miss | within tolerance | peak value |")


# targets.csv writes its numbers to 4 significant digits, the miss and tolerance to 3
TARGET_FORMATS = {**dict.fromkeys(TARGET_COLUMNS, ".4g"), "relative_miss": ".3g", "tolerance": ".3g"}


def target_table(calibration: Calibration, results: list[TargetResult]) -> pd.DataFrame:
    """One row per target (TARGET_COLUMNS, typed; None where there is no value); miss and tolerance are
    relative to the paper's optimum."""
    import pandas as pd

    rows = []
    for index, (target, result) in enumerate(zip(calibration.spec.targets, results, strict=True)):
        band = target.band_hz or (None, None)
        reached = result.band_80 or (None, None)
        rows.append({
            "label": result.label, "metric": calibration.metric(index),
            "paper_optimum_hz": target.optimum_hz, "paper_band_low_hz": band[0], "paper_band_high_hz": band[1],
            "resonance_estimate_hz": result.resonance_hz, "main_lobe_optimum_hz": result.optimum,
            "main_lobe_band_80_low_hz": reached[0], "main_lobe_band_80_high_hz": reached[1],
            "global_max_optimum_hz": result.global_optimum, "relative_miss": result.miss,
            "tolerance": target.tolerance, "within_tolerance": "yes" if abs(result.miss) <= target.tolerance else "no",
            "main_lobe_peak_value": result.optimum_value or 0.0, "global_max_peak_value": result.best_value or 0.0,
            "failed_runs": result.failed,
        })
    return pd.DataFrame(rows, columns=list(TARGET_COLUMNS), dtype=object)


def _shown(value: float | None) -> str:
    return "" if value is None else format(value, ".4g")


def targets_markdown(calibration: Calibration, table: pd.DataFrame, refine_note: str) -> str:
    """The per-target table in Markdown."""
    lines = [f"# Calibration `{calibration.spec.name}`: reached optima", "",
             f"Main lobe: the lobe whose peak is nearest (log frequency) to the rock-mode estimate; {refine_note}.",
             "", HEADER, "|---|---|---|---|---|---|---|---|"]
    for row in table.to_dict("records"):
        paper = _shown(row["paper_optimum_hz"]) + (f" ({_shown(row['paper_band_low_hz'])}-"
                                                   f"{_shown(row['paper_band_high_hz'])})"
                                                   if row["paper_band_low_hz"] is not None else "")
        main = _shown(row["main_lobe_optimum_hz"]) or "none"
        if row["main_lobe_band_80_low_hz"] is not None:
            main += f" ({_shown(row['main_lobe_band_80_low_hz'])}-{_shown(row['main_lobe_band_80_high_hz'])})"
        lines.append(f"| {row['label']} | {row['metric']} | {paper} | {main} | "
                     f"{_shown(row['global_max_optimum_hz']) or 'none'} | {row['relative_miss']:+.1%} | "
                     f"{row['within_tolerance']} (±{row['tolerance']:.0%}) | {_shown(row['main_lobe_peak_value']) or '0'} |")
    return "\n".join(lines) + "\n"


def pareto_rows(calibration: Calibration, records: list[CalibrationEvaluation]) -> list[dict[str, Any]]:
    """The non-dominated evaluations over the |misses|, by objective: parameters, signed misses,
    rising penalty, objective."""
    misses = np.array([[abs(t.miss) for t in r.targets] for r in records])
    front = sorted(non_dominated(misses), key=lambda i: records[i].objective)
    return [{"evaluation": i, "objective": records[i].objective, "rising_penalty": records[i].rising_penalty,
             **records[i].parameters,
             **{f"miss {label}": t.miss for label, t in zip(calibration.labels, records[i].targets, strict=True)}}
            for i in front]


def write_report(directory: Path, calibration: Calibration, result: SearchResult,
                 sessions: list[dict[str, Any]]) -> None:
    """Every output file of a calibration with a best evaluation (module docstring)."""
    best, final = result.best, result.final
    scene = calibration.scene(best.parameters).model_dump(mode="json", by_alias=True, exclude_none=True)
    write_resolved(directory / "calibrated_scene.yaml", scene)
    table = target_table(calibration, final.results)
    write_table(directory / "targets.csv", table, TARGET_FORMATS)
    step = calibration.spec.refine_hz
    note = (f"optima of the best parameter set scanned again with points every {step:g} Hz around its optima"
            if step else "optima on the calibration's frequency axis")
    (directory / "targets.md").write_text(targets_markdown(calibration, table, note), encoding="utf-8")
    pareto = pareto_rows(calibration, result.records)
    write_rows_csv(directory / "pareto.csv", pareto, list(pareto[0]))
    curves = [{"target": label, "frequency_hz": f, "metric": calibration.metric(t), "value": v}
              for t, (label, (frequencies, values)) in enumerate(zip(calibration.labels, final.curves, strict=True))
              for f, v in zip(frequencies, values, strict=True)]
    write_rows_csv(directory / "best_curves.csv", curves, ["target", "frequency_hz", "metric", "value"])
    write_json(directory / "calibration.json", {
        "calibration": calibration.spec.model_dump(mode="json", by_alias=True), "hash": calibration.hash,
        "best": best, "report": final.results,
        "cost": {"sessions": sessions, "wall_time_s": sum(s["wall_time_s"] for s in sessions),
                 "simulation_cpu_time_s": sum(s["simulation_cpu_time_s"] for s in sessions),
                 "simulations": sum(s["simulations"] for s in sessions), "evaluations": len(result.records)},
        "evaluations": result.records})
