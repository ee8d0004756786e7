"""``rpdrill accuracy STUDY.yaml --out DIR``: a work-precision study (what accuracy costs in CPU time; the
library's ``rpdrill.accuracy``: studies.accuracy.accuracy_run).

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

from ..accuracy.accuracy_run import TABLE, TAKES, ReferenceFailed, accuracy
from .options import add_resumable_arguments, run_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_resumable_arguments(parser, "study", "work-precision study YAML file (studies/accuracy_studies/*.yaml)")


def run(args: argparse.Namespace) -> int:
    try:
        result = accuracy(args.study, run_options(args, *TAKES), allow_code=args.allow_code)
    except ReferenceFailed as error:
        print(error, file=sys.stderr)
        return 1
    study, table, out = result.study, result.table, result.out
    for what, seconds in result.reference_cpu_s.items():
        setting = study.reference if what == "reference" else study.reference_check
        print(f"{study.spec.name}: {what} {setting.solver} ({seconds:.2f} s)", file=sys.stderr)
    failed = table[table["status"] != "ok"]
    print(f"{study.spec.name}: {len(table) - len(failed)} settings ok, {len(failed)} failed; wrote {out / TABLE}, "
          f"{out / 'pareto.csv'}, {out / 'reference.json'}, {', '.join(map(str, result.figures))}", file=sys.stderr)
    shown = failed.head(5)
    for family, setting, value, error in zip(shown["family"], shown["setting"], shown["value"], shown["error"]):
        print(f"  {family} {setting} {value}: {error}", file=sys.stderr)
    report = result.report
    for measure, ok in report.get("agreement_below_smallest_error", {}).items():
        print(f"  references agree to {report['agreement'][measure]:.3g} in {measure}; smallest plotted error "
              f"{report['smallest_plotted_error'][measure]:.3g}" + ("" if ok else "  <-- NOT below"),
              file=sys.stderr)
    return 0 if result.references_agree else 1
