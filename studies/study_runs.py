"""Running studies into their output folders: the points of several studies as one run on one pool,
each study's results table, optima and plots (the library's ``run_study`` and the ``rpdrill study``
command both run through :func:`run_study_files` / :func:`run_studies`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .figures.plot_tasks import start_plots
from .inputs.reading import InputError
from .runtime.output_files import check_out, write_json, write_rows_csv
from .runtime.point_runs import point_columns, run_point
from .runtime.pools import Runner, pool, sequential
from .runtime.resumable import RECORD, Table, run_tables
from .runtime.run_options import RunOptions
from .scan.continuation_runs import continuation_table, sort_files
from .scan.curve_optima import Optimum
from .scan.study import Study, StudyPoint, load_study
from .scan.study_optima import csv_rows, study_optima

if TYPE_CHECKING:
    import pandas as pd


def write_optima(study: Study, out: Path, table: pd.DataFrame, record: dict[str, Any]) -> list[Optimum]:
    """The study's optima (studies.scan.study_optima) into optima.csv and, beside its ``record``, study.json."""
    optima = study_optima(study, table)
    write_rows_csv(out / "optima.csv", csv_rows(optima))
    write_json(out / "study.json", {**record, "optima": [optimum.record for optimum in optima]})
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


@dataclass(frozen=True)
class StudyRun:
    """A study run into its folder: the results ``table`` (one row a point, in point order), its optima,
    the plot files written and the plots left out (none of their metrics has a value)."""

    study: Study
    out: Path
    table: pd.DataFrame
    optima: list[Optimum]
    plots: list[Path]
    skipped_plots: list[str]


def _task(point: StudyPoint) -> object:
    return point.simulation


def run_studies(studies: list[Study], folders: list[Path], runner: tuple[str, Runner], plots_here: bool,
                quiet: bool) -> list[StudyRun]:
    """Run the studies' points on ``runner`` into their folders as one run (studies.runtime.resumable.run_tables:
    the workers go from one study to the next without waiting, a point whose scene another study has
    runs once; each point studies.runtime.point_runs.run_point); as each study completes, its optima are
    written and its plots handed to the workers (``plots_here``: drawn in this process, as with Dask,
    whose workers may write on another machine)."""
    started: dict[int, tuple[list[Optimum], Callable[[], tuple[list[Path], list[str]]]]] = {}

    def finished(i: int, table: pd.DataFrame, record: dict[str, Any]) -> None:
        if studies[i].spec.steady_state == "continuation":
            sort_files(studies[i], folders[i])
        optima = write_optima(studies[i], folders[i], table, record)
        started[i] = optima, start_plots(studies[i], table, optima, folders[i],
                                         sequential if plots_here else runner[1])

    tables = [_table(study, out) for study, out in zip(studies, folders, strict=True)]
    frames = run_tables(tables, runner, quiet, finished)
    return [StudyRun(study, out, table, started[i][0], *started[i][1]())
            for i, (study, out, table) in enumerate(zip(studies, folders, frames, strict=True))]


def _table(study: Study, out: Path) -> Table:
    """The results table of a study: each point run by a worker, or, for a continuation study, each chain
    (studies.scan.continuation_runs), the rows of its points from its outcome."""
    columns = ["point", *study.axes, *point_columns(study.spec.metrics)]
    if study.spec.steady_state == "continuation":
        return continuation_table(study, out, columns)
    return Table(study, out, "results.csv", columns, _task, run_point, scene_keys=study.scene_keys)


STUDY_OPTIONS = ("workers", "dask", "out", "budget", "quiet")  # the run options of a study (rpdrill.RunOptions)


def run_study_files(paths: Sequence[str | Path], options: RunOptions, formulation: str | None = None,
                    allow_code: Sequence[str] | str = ()) -> list[StudyRun]:
    """Read the study files (InputError or BudgetError before anything runs; ``allow_code``: the modules of one's
    own their scenes may run), then run them as ``options`` say into ``options.out`` (one study) or
    ``options.out``/<file stem> (several)."""
    options = RunOptions.of("rpdrill study", options, {}, STUDY_OPTIONS)
    if options.out is None:
        raise InputError("rpdrill study: --out: give the folder the studies write into")
    folders = study_folders([str(path) for path in paths], str(options.out))
    studies = [load_study(path, formulation, options.budget, allow_code) for path in paths]
    with pool(options.dask, options.workers) as runner:
        return run_studies(studies, folders, runner, options.dask is not None, options.quiet)
