"""``rpdrill study STUDY.yaml [STUDY.yaml ...] --out DIR``: run YAML studies (scans of scenes) on all
cores or a Dask cluster.

Running again into the same DIR skips finished points; a changed study, and a DIR holding anything
else, are refused (studies.runtime.resumable). Every study is read and every point and study checked against
the budgets before any runs (studies.runtime.budgets). Several studies run on one pool of workers as one
run, each into DIR/<its file name without .yaml>: the workers go from one study's points to the
next, a point whose scene equals another's runs once (the paper's impulse scan repeats the
frequency scan at 220 kN), and a study's plots are drawn by the workers once its points are done.
The exit status is 1 when some point failed, or no point of a study is usable (its status ok or
unsettled: models.evaluation.run_status). What DIR holds: FILES below.
"""

from __future__ import annotations

import argparse
import sys

from ...models.definition.formulations import FORMULATIONS
from ...models.evaluation.run_status import STATUSES, USABLE
from ..api import run_study_files
from ..inputs.arguments import choice_problem, cli_type
from ..scan.study_optima import optima_table
from ..study_runs import STUDY_OPTIONS, StudyRun
from .options import add_resumable_arguments, run_options

FILES = """files written to DIR (to DIR/<file name without .yaml> for each of several studies):
  results.csv    one row per point (scan values, status, error, wall time, metrics in SI units),
                 appended as points finish
  study.json     provenance (study hash, versions, the resolved study, sessions, wall time per
                 point) and the optima
  optima.csv     per curve and figure of merit: the best grid point, the refined optimum of the
                 main lobe with its value, the 80 % and 50 % bands (studies/scan/study_optima.py)
  NN_NAME.png    each plot of the study (and .svg beside it; format: svg or pdf as the study says)"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = FILES
    add_resumable_arguments(parser, "study", "study YAML file(s)", many=True)
    parser.add_argument("--formulation", type=cli_type(choice_problem(FORMULATIONS, "formulation")),
                        metavar="{" + ",".join(FORMULATIONS) + "}",
                        help="run every point with this formulation (default: the scene's solver.formulation)")


def report(run: StudyRun) -> None:
    """What a study wrote and its failed points (stderr), its optima table (stdout)."""
    status, out = run.table["status"], run.out
    counts = status.value_counts()
    kinds = ", ".join(f"{counts[kind]} {kind}" for kind in STATUSES[1:] if kind in counts)
    print(f"{run.study.spec.name}: {counts.get('ok', 0)} points ok, {kinds + ', ' if kinds else ''}"
          f"{counts.get('failed', 0)} failed; wrote "
          f"{out / 'results.csv'}, {out / 'study.json'}, {out / 'optima.csv'}" + "".join(f", {p}" for p in run.plots),
          file=sys.stderr)
    if run.skipped_plots:
        print(f"  no plot {', '.join(run.skipped_plots)}: no point has a result for its metrics", file=sys.stderr)
    failed_first = [run.table[status == "failed"], run.table[~status.isin(("ok", "failed"))]]
    shown = [(p, k, e) for part in failed_first for p, k, e in zip(part["point"], part["status"], part["error"])][:5]
    for point, kind, error in shown:
        print(f"  point {point} ({kind}): {error}", file=sys.stderr)
    table = optima_table(run.optima)
    print(table or f"{run.study.spec.name}: no optima (no figure of merit collected, or no numeric axis with "
                    "three or more values)")


def run(args: argparse.Namespace) -> int:
    runs = run_study_files(args.study, run_options(args, *STUDY_OPTIONS), formulation=args.formulation,
                           allow_code=args.allow_code)
    for study_run in runs:
        report(study_run)
    useless = [study_run.study.source for study_run in runs if not study_run.table["status"].isin(USABLE).any()]
    for source in useless:
        print(f"{source}: no point gave figures that stand (status {' or '.join(USABLE)}); nothing to compare: "
              "see the errors in results.csv", file=sys.stderr)
    return 1 if useless or any((study_run.table["status"] == "failed").any() for study_run in runs) else 0
