"""``rpdrill study STUDY.yaml --out DIR``: run a YAML study (a scan of scenes) on all cores or a Dask cluster.

Writes DIR/results.csv (one row per point, appended batch by batch as points finish), DIR/study.json
(provenance) and the study's plots (drawn by the workers once the results are complete). Running again into the same DIR skips finished points;
a changed study is refused (studies.resumable). The exit status is 1 when some point failed.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from pathlib import Path

from rpdrill.studies.commands import add_runner_arguments
from rpdrill.studies.plots.scans import draw_plot, plot_tasks
from rpdrill.studies.points import run_point
from rpdrill.studies.resumable import STATUS_COLUMNS, Row, run_points
from rpdrill.studies.runners import Runner, pool
from rpdrill.studies.study import Study, load_study


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", help="study YAML file")
    parser.add_argument("--out", required=True, help="output directory (reused to resume)")
    add_runner_arguments(parser)


def run_study(study: Study, out: Path, runner: tuple[str, Runner], quiet: bool) -> tuple[list[Row], Iterator[list[Path]]]:
    """Run the study's points into ``out``, then hand its plots to the runner's workers: (all rows, the
    plots as they are written). The plots go on while the caller waits for other work."""
    columns = ["point", *study.axes, *STATUS_COLUMNS, *study.spec.metrics]
    rows = run_points(study, out, "results.csv", columns, lambda p: (p.index, p.simulation), run_point, runner, quiet)
    return rows, runner[1](draw_plot, plot_tasks(study, rows, out))


def report(study: Study, out: Path, rows: list[Row], written: list[Path]) -> int:
    """Print what was written and the first failures; the exit status (1 when some point failed)."""
    failed = [row for row in rows if row["status"] != "ok"]
    print(f"{study.spec.name}: {len(rows) - len(failed)} points ok, {len(failed)} failed; wrote "
          f"{out / 'results.csv'}, {out / 'study.json'}" + "".join(f", {p}" for p in written), file=sys.stderr)
    for row in failed[:5]:
        print(f"  point {row['point']}: {row['error']}", file=sys.stderr)
    return 1 if failed else 0


def run(args: argparse.Namespace) -> int:
    study = load_study(args.study)
    out = Path(args.out)
    with pool(args.dask, args.workers) as runner:
        rows, plots = run_study(study, out, runner, args.quiet)
        written = sorted(path for batch in plots for path in batch)
    return report(study, out, rows, written)
