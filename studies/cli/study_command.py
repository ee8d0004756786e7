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
from pathlib import Path

from ...models.definition.formulations import FORMULATIONS
from ...models.evaluation.run_status import STATUSES, USABLE
from ..api import run_study_files
from ..inputs.arguments import choice_problem, cli_type
from ..runtime.resumable import Row
from ..scan.study import Study
from ..scan.study_optima import Record, optima_table
from .options import add_resumable_arguments, budget

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


def report(study: Study, out: Path, rows: list[Row], optima: list[Record], written: list[Path],
           skipped: list[str]) -> None:
    """What a study wrote and its failed points (stderr), its optima table (stdout)."""
    failed = [row for row in rows if row["status"] == "failed"]
    flagged = [row for row in rows if row["status"] not in ("ok", "failed")]
    kinds = ", ".join(f"{sum(r['status'] == kind for r in flagged)} {kind}" for kind in STATUSES[1:]
                      if any(r["status"] == kind for r in flagged))
    print(f"{study.spec.name}: {len(rows) - len(failed) - len(flagged)} points ok, {kinds + ', ' if kinds else ''}"
          f"{len(failed)} failed; wrote "
          f"{out / 'results.csv'}, {out / 'study.json'}, {out / 'optima.csv'}" + "".join(f", {p}" for p in written),
          file=sys.stderr)
    if skipped:
        print(f"  no plot {', '.join(skipped)}: no point has a result for its metrics", file=sys.stderr)
    for row in (failed + flagged)[:5]:
        print(f"  point {row['point']} ({row['status']}): {row['error']}", file=sys.stderr)
    table = optima_table(optima)
    print(table or f"{study.spec.name}: no optima (no figure of merit collected, or no numeric axis with "
                    "three or more values)")


def run(args: argparse.Namespace) -> int:
    outcomes = run_study_files(args.study, args.out, formulation=args.formulation, budget=budget(args),
                               workers=args.workers, dask=args.dask, quiet=args.quiet)
    for outcome in outcomes:
        report(*outcome)
    useless = [outcome[0].source for outcome in outcomes if not any(r["status"] in USABLE for r in outcome[2])]
    for source in useless:
        print(f"{source}: no point gave figures that stand (status {' or '.join(USABLE)}); nothing to compare: "
              "see the errors in results.csv", file=sys.stderr)
    return 1 if useless or any(row["status"] == "failed" for outcome in outcomes for row in outcome[2]) else 0
