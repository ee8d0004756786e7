"""``rpdrill study STUDY.yaml --out DIR``: run a YAML study (a scan of scenes) on all cores or a Dask cluster.

Running again into the same DIR skips finished points; a changed study, and a DIR holding anything
else, are refused (studies.resumable). Every point and the whole study are checked against the
budgets before any runs (studies.budgets). The exit status is 1 when some point failed. What DIR
holds: FILES below.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from rpdrill.models.formulations import FORMULATIONS
from rpdrill.studies.commands import add_resumable_arguments, budget
from rpdrill.studies.points import run_point
from rpdrill.studies.resumable import RECORD, STATUS_COLUMNS, Row, run_points
from rpdrill.studies.run_files import check_out, write_json, write_rows_csv
from rpdrill.studies.runners import Runner, pool
from rpdrill.studies.study import Study, load_study
from rpdrill.studies.study_optima import Record, csv_rows, optima_table, study_optima

FILES = """files written to DIR:
  results.csv    one row per point (scan values, status, error, wall time, metrics in SI units),
                 appended as points finish
  study.json     provenance (study hash, versions, the resolved study, sessions, wall time per
                 point) and the optima
  optima.csv     per curve and figure of merit: the best grid point, the refined optimum of the
                 main lobe with its value, the 80 % and 50 % bands (studies/study_optima.py)
  NN_NAME.png    each plot of the study (and .svg beside it; format: svg or pdf as the study says)"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = FILES
    add_resumable_arguments(parser, "study", "study YAML file")
    parser.add_argument("--formulation", choices=tuple(FORMULATIONS),
                        help="run every point with this formulation (default: the scene's solver.formulation)")


def run_study(study: Study, out: Path, runner: tuple[str, Runner], quiet: bool) -> tuple[list[Row], list[Record]]:
    """Run the study's points into ``out`` (resumable), then write its optima (optima.csv, study.json):
    (all rows, the optima)."""
    columns = ["point", *study.axes, *STATUS_COLUMNS, *study.spec.metrics]
    rows = run_points(study, out, "results.csv", columns, lambda p: (p.index, p.simulation), run_point, runner, quiet)
    optima = study_optima(study, rows)
    write_rows_csv(out / "optima.csv", csv_rows(optima))
    record = json.loads((out / "study.json").read_text(encoding="utf-8"))
    write_json(out / "study.json", {**record, "optima": optima})
    return rows, optima


def run(args: argparse.Namespace) -> int:
    out = check_out(args.out, None, RECORD)
    study = load_study(args.study, args.formulation, budget(args))
    with pool(args.dask, args.workers) as runner:
        rows, optima = run_study(study, out, runner, args.quiet)
        # matplotlib once the points have run, not at start
        from rpdrill.studies.plots.scans import draw_plots

        written, skipped = draw_plots(study, rows, optima, out, runner[1])  # by the workers, side by side
    failed = [row for row in rows if row["status"] != "ok"]
    print(f"{study.spec.name}: {len(rows) - len(failed)} points ok, {len(failed)} failed; wrote "
          f"{out / 'results.csv'}, {out / 'study.json'}, {out / 'optima.csv'}" + "".join(f", {p}" for p in written),
          file=sys.stderr)
    if skipped:
        print(f"  no plot {', '.join(skipped)}: no point has a result for its metrics", file=sys.stderr)
    for row in failed[:5]:
        print(f"  point {row['point']}: {row['error']}", file=sys.stderr)
    table = optima_table(optima)
    print(table or f"{study.spec.name}: no optima (no figure of merit collected, or no numeric axis with "
                    "three or more values)")
    return 1 if failed else 0
