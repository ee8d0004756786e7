"""``rpdrill accuracy STUDY.yaml --out DIR``: a work-precision study (what accuracy costs in CPU time).

Runs the study's reference and reference check in this process, then every solver setting
``repeats`` times on all cores (or ``--workers``), and writes

* DIR/workprecision.csv: one row per setting (appended as settings finish, resumable as for
  ``rpdrill study``): median CPU time, every repeat's CPU time, and the errors of
  models.evaluation.workprecision against the reference; a diverged or failed setting is a row with status
  ``failed`` and its message;
* DIR/pareto.csv: the Pareto front (cheapest settings for their accuracy) of each error measure;
* DIR/reference.json: both references, their agreement, and whether it is below the smallest
  plotted error (so the plotted errors are errors of the settings, not of the reference);
* DIR/workprecision.png (and .svg): error against CPU time, log-log, one line per solver family,
  one panel per error measure, the Pareto front and the references' agreement marked;
* DIR/study.json: provenance (as ``rpdrill study``).

Exit status 0 when the study ran (failed settings are results), 1 when the reference failed or
the references do not agree better than the smallest plotted error, 2 for bad input.
"""

from __future__ import annotations

import argparse
import sys
import time

from ...models.evaluation.workprecision import Signature
from ..accuracy.accuracy_study import (
    COLUMNS,
    PARETO_COLUMNS,
    AccuracyStudy,
    Setting,
    load_accuracy_study,
    outcome_row,
    pareto_rows,
    reference_report,
    reference_signature,
    run_setting,
)
from ..figures.workprecision_figure import plot_workprecision
from ..runtime.interrupts import raise_if_stopped
from ..runtime.output_files import check_out, write_json, write_rows_csv
from ..runtime.pools import pool
from ..runtime.resumable import RECORD, run_points
from .options import add_resumable_arguments, budget


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_resumable_arguments(parser, "study", "work-precision study YAML file (studies/accuracy_studies/*.yaml)")


def _reference(study: AccuracyStudy, setting: Setting | None, what: str) -> Signature | None:
    if setting is None:
        return None
    start = time.perf_counter()
    sig = reference_signature(study, setting)
    print(f"{study.spec.name}: {what} {setting.solver} "
          f"({time.perf_counter() - start:.2f} s)", file=sys.stderr)
    return sig


def run(args: argparse.Namespace) -> int:
    out = check_out(args.out, None, RECORD)
    study = load_accuracy_study(args.study, budget(args))
    try:
        reference = _reference(study, study.reference, "reference")
        check = _reference(study, study.reference_check, "reference check")
    except Exception as err:  # noqa: BLE001 - no reference, no study
        raise_if_stopped()  # the run was cut by Ctrl-C or SIGTERM
        print(f"{args.study}: the reference failed: {type(err).__name__}: {err}", file=sys.stderr)
        return 1
    spec = study.spec
    with pool(args.dask, args.workers) as runner:
        rows = run_points(study, out, "workprecision.csv", COLUMNS,
                          lambda p: (p.index, study.scene, study.runs[p.index], spec.grid_interval_s, spec.time_limit_s),
                          run_setting, runner, args.quiet, lambda outcome: outcome_row(study, reference, outcome))
    front = pareto_rows(rows)
    write_rows_csv(out / "pareto.csv", front, PARETO_COLUMNS)
    report = reference_report(study, reference, check, rows)
    write_json(out / "reference.json", report)
    plots = plot_workprecision(study, rows, front, report, out / f"workprecision.{spec.format}")
    failed = [row for row in rows if row["status"] != "ok"]
    print(f"{spec.name}: {len(rows) - len(failed)} settings ok, {len(failed)} failed; wrote {out / 'workprecision.csv'}, "
          f"{out / 'pareto.csv'}, {out / 'reference.json'}, {', '.join(map(str, plots))}", file=sys.stderr)
    for row in failed[:5]:
        print(f"  {row['family']} {row['setting']} {row['value']}: {row['error']}", file=sys.stderr)
    below = report.get("agreement_below_smallest_error", {})
    for measure, ok in below.items():
        print(f"  references agree to {report['agreement'][measure]:.3g} in {measure}; smallest plotted error "
              f"{report['smallest_plotted_error'][measure]:.3g}" + ("" if ok else "  <-- NOT below"),
              file=sys.stderr)
    return 0 if all(below.values()) else 1
