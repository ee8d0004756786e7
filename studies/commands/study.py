"""``rpdrill study STUDY.yaml --out DIR``: run a YAML study (a scan of scenes) on all cores or a Dask cluster.

Writes DIR/results.csv (one row per point, appended as points finish), DIR/study.json
(provenance) and the study's plots. Running again into the same DIR skips finished points;
a changed study, and a DIR holding anything else, are refused (studies.resumable). Every point and
the whole study are checked against the budgets before any runs (studies.budgets). The exit status
is 1 when some point failed.
"""

from __future__ import annotations

import argparse
import sys

from rpdrill.studies.commands import add_budget_arguments, add_runner_arguments, budget
from rpdrill.studies.plots.scans import draw_plots
from rpdrill.studies.points import run_point
from rpdrill.studies.resumable import RECORD, STATUS_COLUMNS, run_points
from rpdrill.studies.run_files import check_out
from rpdrill.studies.runners import pool
from rpdrill.studies.study import load_study


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", help="study YAML file")
    parser.add_argument("--out", required=True, help="output directory: new, empty, or this study's (to resume)")
    add_runner_arguments(parser)
    add_budget_arguments(parser)


def run(args: argparse.Namespace) -> int:
    out = check_out(args.out, None, RECORD)
    study = load_study(args.study, budget(args))
    columns = ["point", *study.axes, *STATUS_COLUMNS, *study.spec.metrics]
    with pool(args.dask, args.workers) as runner:
        rows = run_points(study, out, "results.csv", columns, lambda p: (p.index, p.simulation), run_point, runner,
                          args.quiet)
    written = draw_plots(study, rows, out)
    failed = [row for row in rows if row["status"] != "ok"]
    print(f"{study.spec.name}: {len(rows) - len(failed)} points ok, {len(failed)} failed; wrote "
          f"{out / 'results.csv'}, {out / 'study.json'}" + "".join(f", {p}" for p in written), file=sys.stderr)
    for row in failed[:5]:
        print(f"  point {row['point']}: {row['error']}", file=sys.stderr)
    return 1 if failed else 0
