"""``rpdrill accuracy STUDY.yaml --out DIR``: a work-precision study (what accuracy costs in CPU time).

Runs the study's reference and reference check in this process, then every solver setting
``repeats`` times on all cores (or ``--workers``), and writes

* DIR/workprecision.csv: one row per setting (appended as settings finish, resumable as for
  ``rpdrill study``): median CPU time, every repeat's CPU time, and the errors of
  models.workprecision against the reference; a diverged or failed setting is a row with status
  ``failed`` and its message;
* DIR/pareto.csv: the Pareto front (cheapest settings for their accuracy) of each error measure;
* DIR/reference.json: both references, their agreement, and whether it is below the smallest
  plotted error (so the plotted errors are errors of the settings, not of the reference);
* DIR/workprecision.png: error against CPU time, log-log, one line per solver family, one panel
  per error measure, the Pareto front and the references' agreement marked;
* DIR/study.json: provenance (as ``rpdrill study``).

Exit status 0 when the study ran (failed settings are results), 1 when the reference failed or
the references do not agree better than the smallest plotted error, 2 for bad input.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from collections import defaultdict
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from tqdm import tqdm

from rpdrill.models.workprecision import ERROR_LABELS, ERROR_MEASURES, Signature, errors, pareto_front
from rpdrill.studies.accuracy import (
    AccuracyStudy,
    Setting,
    load_accuracy_study,
    reference_signature,
    run_setting,
)
from rpdrill.studies.outputs import write_json
from rpdrill.studies.runners import select
from rpdrill.studies.study_command import finished_rows, read_results, result_row, study_provenance

PARAMETERS = ("family", "formulation", "solver", "setting", "value")
STATUS = ("status", "error", "wall_time_s")
VALUES = ("cpu_time_s", "cpu_time_s_runs", "bottom_end_error_m", *ERROR_MEASURES, "penetration_rate_m_per_s")
COLUMNS = ["point", *PARAMETERS, *STATUS, *VALUES]
Row = dict[str, str]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", help="work-precision study YAML file (studies/accuracy/*.yaml)")
    parser.add_argument("--out", required=True, help="output directory (reused to resume)")
    parser.add_argument("--workers", type=int, help="worker processes (default: all cores; 1: in this process)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def _outcome_row(study: AccuracyStudy, reference: Signature, outcome: dict[str, Any]) -> dict[str, Any]:
    """The CSV row of a finished setting, its errors measured against ``reference``."""
    if outcome["status"] == "ok":
        sig: Signature = outcome["signature"]
        outcome["metrics"].update({k: f"{v:.6g}" for k, v in errors(reference, sig).items()},
                                  penetration_rate_m_per_s=f"{sig.penetration_rate_m_per_s:.10g}")
        outcome["metrics"]["cpu_time_s"] = f"{outcome['metrics']['cpu_time_s']:.6g}"
    return result_row(study.points[outcome["point"]], outcome)


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def pareto_rows(rows: list[Row]) -> list[dict[str, Any]]:
    """The Pareto front of every error measure over the settings that ran."""
    ok = [r for r in rows if r["status"] == "ok"]
    out = []
    for measure in ERROR_MEASURES:
        cost, error = [_float(r["cpu_time_s"]) for r in ok], [_float(r[measure]) for r in ok]
        for i in pareto_front(cost, error):
            out.append({"measure": measure, **{k: ok[i][k] for k in ("point", *PARAMETERS)},
                        "cpu_time_s": ok[i]["cpu_time_s"], "error": ok[i][measure]})
    return out


def _write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, list(rows[0]) if rows else ["measure"])
        writer.writeheader()
        writer.writerows(rows)


def smallest_errors(rows: list[Row]) -> dict[str, float]:
    """The smallest positive error of each measure over the settings that ran (what the plot shows)."""
    out = {}
    for measure in ERROR_MEASURES:
        values = [v for v in (_float(r[measure]) for r in rows if r["status"] == "ok") if v > 0 and math.isfinite(v)]
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


def plot_workprecision(study: AccuracyStudy, rows: list[Row], front: list[dict[str, Any]],
                       report: dict[str, Any], path: Path) -> None:
    """Error against median CPU time, log-log, one panel per measure, one line per family."""
    fig, axes = plt.subplots(1, len(ERROR_MEASURES), figsize=(6 * len(ERROR_MEASURES), 5.5))
    families: dict[str, list[Row]] = defaultdict(list)
    for row in sorted(rows, key=lambda r: int(r["point"])):
        families[row["family"]].append(row)
    markers = "osD^v<>ph*X"
    colors = plt.cm.tab20(range(20))
    for ax, measure in zip(axes, ERROR_MEASURES):
        for k, (label, members) in enumerate(families.items()):
            pairs = [(_float(r["cpu_time_s"]), _float(r[measure])) for r in members if r["status"] == "ok"]
            pairs = [(c, e) for c, e in pairs if c > 0 and e > 0 and math.isfinite(e)]
            failed = sum(r["status"] != "ok" for r in members)
            name = label + (f" ({failed} failed)" if failed else "")
            if pairs:
                ax.loglog(*zip(*pairs), marker=markers[k % len(markers)], ms=4, lw=1, label=name,
                          color=colors[(2 * k) % 20 + (k // 10) % 2])
            else:
                ax.plot([], [], marker=markers[k % len(markers)], label=name, color=colors[(2 * k) % 20])
        points = [(_float(p["cpu_time_s"]), _float(p["error"])) for p in front if p["measure"] == measure]
        points = [(c, e) for c, e in points if c > 0 and e > 0]
        if points:
            ax.step(*zip(*points), where="post", color="k", ls="--", lw=1, label="Pareto front")
            ax.plot(*zip(*points), "o", mfc="none", mec="k", ms=9)
        agreement = report.get("agreement", {}).get(measure)
        if agreement and agreement > 0:
            ax.axhline(agreement, color="gray", ls=":", lw=1, label="references' agreement")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("CPU time [s] (median of repeats)")
        ax.set_ylabel(ERROR_LABELS[measure])
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{study.spec.name}: {study.spec.blows} blows, reference {study.reference.formulation}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _reference(study: AccuracyStudy, setting: Setting | None, what: str) -> Signature | None:
    if setting is None:
        return None
    start = time.perf_counter()
    sig = reference_signature(study, setting)
    print(f"{study.spec.name}: {what} {setting.solver} "
          f"({time.perf_counter() - start:.2f} s)", file=sys.stderr)
    return sig


def run(args: argparse.Namespace) -> int:
    study = load_accuracy_study(args.study)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    provenance = study_provenance(study, out)  # type: ignore[arg-type]  # duck-typed like a Study
    write_json(out / "study.json", provenance)
    try:
        reference = _reference(study, study.reference, "reference")
        check = _reference(study, study.reference_check, "reference check")
    except Exception as err:  # noqa: BLE001 - no reference, no study
        print(f"{study.spec.name}: the reference failed: {type(err).__name__}: {err}", file=sys.stderr)
        return 1
    results = out / "workprecision.csv"
    done = finished_rows(results, COLUMNS, len(study.points))
    todo = [p for p in study.points if p.index not in done]
    label, runner = select(None, args.workers)
    print(f"{study.spec.name}: {len(study.points)} settings, {len(done)} finished earlier, "
          f"running {len(todo)} on {label}", file=sys.stderr)
    start = time.perf_counter()
    tasks = [(p.index, study.scene, study.runs[p.index], study.spec.grid_interval_s, study.spec.time_limit_s)
             for p in todo]
    with results.open("a", newline="", encoding="utf-8") as handle, \
            tqdm(total=len(study.points), initial=len(done), desc=study.spec.name, unit="setting",
                 disable=args.quiet) as bar:
        writer = csv.DictWriter(handle, COLUMNS)
        for outcome in runner(run_setting, tasks) if tasks else ():
            writer.writerow(_outcome_row(study, reference, outcome))
            handle.flush()
            bar.update(1)
    rows = read_results(results)
    front = pareto_rows(rows)
    _write_csv(out / "pareto.csv", front)
    report = reference_report(study, reference, check, rows)
    write_json(out / "reference.json", report)
    plot = out / f"workprecision.{study.spec.format}"
    plot_workprecision(study, rows, front, report, plot)
    provenance["sessions"].append({"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                                   "runner": label, "points_run": len(todo),
                                   "wall_time_s": round(time.perf_counter() - start, 3)})
    write_json(out / "study.json", provenance)
    failed = [row for row in rows if row["status"] != "ok"]
    print(f"{study.spec.name}: {len(rows) - len(failed)} settings ok, {len(failed)} failed; wrote {results}, "
          f"{out / 'pareto.csv'}, {out / 'reference.json'}, {plot}", file=sys.stderr)
    for row in failed[:5]:
        print(f"  {row['family']} {row['setting']} {row['value']}: {row['error'][:160]}", file=sys.stderr)
    below = report.get("agreement_below_smallest_error", {})
    for measure, ok in below.items():
        print(f"  references agree to {report['agreement'][measure]:.3g} in {measure}; smallest plotted error "
              f"{report['smallest_plotted_error'][measure]:.3g}" + ("" if ok else "  <-- NOT below"),
              file=sys.stderr)
    return 0 if all(below.values()) else 1
