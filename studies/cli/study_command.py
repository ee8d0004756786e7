"""``rpdrill study STUDY.yaml [STUDY.yaml ...] --out DIR``: run YAML studies (scans of scenes) on all
cores or a Dask cluster.

Running again into the same DIR skips finished points; a changed study, and a DIR holding anything
else, are refused (studies.runtime.resumable). Every study is read and every point and study checked against
the budgets before any runs (studies.runtime.budgets). Several studies run on one pool of workers as one
run, each into DIR/<its file name without .yaml>: the workers go from one study's points to the
next, a point whose scene equals another's runs once (the paper's impulse scan repeats the
frequency scan at 220 kN), and a study's plots are drawn by the workers once its points are done.
The exit status is 1 when some point failed. What DIR holds: FILES below.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path

from ...models.formulations import FORMULATIONS
from ..figures.plot_tasks import start_plots
from ..inputs.reading import InputError
from ..runtime.output_files import check_out, write_json, write_rows_csv
from ..runtime.point_runs import run_point
from ..runtime.pools import Runner, pool, sequential
from ..runtime.resumable import RECORD, STATUS_COLUMNS, Row, Table, run_tables
from ..scan.study import Study, load_study
from ..scan.study_optima import Record, csv_rows, optima_table, study_optima
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
    parser.add_argument("--formulation", choices=tuple(FORMULATIONS),
                        help="run every point with this formulation (default: the scene's solver.formulation)")


def write_optima(study: Study, out: Path, rows: list[Row]) -> list[Record]:
    """The study's optima (studies.scan.study_optima) into optima.csv and study.json."""
    optima = study_optima(study, rows)
    write_rows_csv(out / "optima.csv", csv_rows(optima))
    record = json.loads((out / "study.json").read_text(encoding="utf-8"))
    write_json(out / "study.json", {**record, "optima": optima})
    return optima


def study_folders(paths: list[str], out: str) -> list[Path]:
    """``--out`` for one study, ``--out``/<file stem> for each of several; InputError when two files
    share a stem, or a folder cannot take its study's files (studies.runtime.output_files.check_out)."""
    if len(paths) == 1:
        return [check_out(out, None, RECORD)]
    stems = [Path(path).stem for path in paths]
    twice = sorted({stem for stem in stems if stems.count(stem) > 1})
    if twice:
        raise InputError(f"study: {', '.join(paths)}: several files named {', '.join(twice)}: each study of a "
                         "command goes to --out/<file name>; give files of different names")
    return [check_out(Path(out) / stem, None, RECORD) for stem in stems]


def report(study: Study, out: Path, rows: list[Row], optima: list[Record], written: list[Path],
           skipped: list[str]) -> None:
    """What a study wrote and its failed points (stderr), its optima table (stdout)."""
    failed = [row for row in rows if row["status"] == "failed"]
    flagged = [row for row in rows if row["status"] not in ("ok", "failed")]
    kinds = ", ".join(f"{sum(r['status'] == kind for r in flagged)} {kind}" for kind in ("unstable", "unsettled")
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


Outcome = tuple[Study, Path, list[Row], list[Record], list[Path], list[str]]


def run_studies(studies: list[Study], folders: list[Path], runner: tuple[str, Runner], plots_here: bool,
                quiet: bool) -> list[Outcome]:
    """Run the studies' points on ``runner`` into their folders as one run (studies.runtime.resumable.run_tables:
    the workers go from one study to the next without waiting, a point whose scene another study has
    runs once); as each study completes, its optima are written and its plots handed to the workers
    (``plots_here``: drawn in this process, as with Dask, whose workers may write on another machine):
    per study (the study, its folder, rows, optima, the plot files written, the plots left out)."""
    started: dict[int, tuple[list[Record], Callable[[], tuple[list[Path], list[str]]]]] = {}

    def finished(i: int, rows: list[Row]) -> None:
        optima = write_optima(studies[i], folders[i], rows)
        started[i] = optima, start_plots(studies[i], rows, optima, folders[i], sequential if plots_here else runner[1])

    tables = [Table(study, out, "results.csv", ["point", *study.axes, *STATUS_COLUMNS, *study.spec.metrics],
                    lambda p: (p.index, p.simulation), run_point, scene_keys=study.scene_keys)
              for study, out in zip(studies, folders, strict=True)]
    all_rows = run_tables(tables, runner, quiet, finished)
    return [(study, out, rows, started[i][0], *started[i][1]())
            for i, (study, out, rows) in enumerate(zip(studies, folders, all_rows, strict=True))]


def run(args: argparse.Namespace) -> int:
    folders = study_folders(args.study, args.out)
    studies = [load_study(path, args.formulation, budget(args)) for path in args.study]
    with pool(args.dask, args.workers) as runner:
        outcomes = run_studies(studies, folders, runner, args.dask is not None, args.quiet)
    for outcome in outcomes:
        report(*outcome)
    return 1 if any(row["status"] == "failed" for outcome in outcomes for row in outcome[2]) else 0
