"""Running studies into their output folders: the points of several studies as one run on one pool,
each study's results table, optima and plots (the library's ``run_study`` and the ``rpdrill study``
command both run through :func:`run_study_files` / :func:`run_studies`)."""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path

from .figures.plot_tasks import start_plots
from .inputs.reading import InputError
from .runtime.budgets import DEFAULT_BUDGET, Budget
from .runtime.output_files import check_out, write_json, write_rows_csv
from .runtime.point_runs import run_point
from .runtime.pools import Runner, pool, sequential
from .runtime.resumable import RECORD, STATUS_COLUMNS, Row, Table, run_tables
from .scan.continuation_runs import follow_study, given_outcome
from .scan.study import Study, load_study
from .scan.study_optima import Record, csv_rows, study_optima


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

    tables = [_table(study, out, runner) for study, out in zip(studies, folders, strict=True)]
    all_rows = run_tables(tables, runner, quiet, finished)
    return [(study, out, rows, started[i][0], *started[i][1]())
            for i, (study, out, rows) in enumerate(zip(studies, folders, all_rows, strict=True))]


def _table(study: Study, out: Path, runner: tuple[str, Runner]) -> Table:
    """The results table of a study: each point run by a worker, or, for a continuation study, its chains
    followed first (studies.scan.continuation_runs) and each point's outcome taken from them."""
    columns = ["point", *study.axes, *STATUS_COLUMNS, *study.spec.metrics]
    if study.spec.steady_state == "continuation":
        followed = follow_study(study, out, runner)
        return Table(study, out, "results.csv", columns, lambda p: followed[p.index], given_outcome)
    return Table(study, out, "results.csv", columns, lambda p: (p.index, p.simulation), run_point,
                 scene_keys=study.scene_keys)


def run_study_files(paths: Sequence[str | Path], out: str | Path, formulation: str | None = None,
                    budget: Budget = DEFAULT_BUDGET, workers: int | None = None, dask: str | None = None,
                    quiet: bool = True) -> list[Outcome]:
    """Read the study files (InputError or BudgetError before anything runs), then run them into ``out``
    (one study) or ``out``/<file stem> (several) on a pool of ``workers`` processes (1: in this process)
    or Dask (``dask``: an address, or "" for a LocalCluster)."""
    folders = study_folders([str(path) for path in paths], str(out))
    studies = [load_study(path, formulation, budget) for path in paths]
    with pool(dask, workers) as runner:
        return run_studies(studies, folders, runner, dask is not None, quiet)
