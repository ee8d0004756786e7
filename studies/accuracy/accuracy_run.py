"""A work-precision study as a library call: :func:`accuracy` is ``rpdrill accuracy`` without its printing
(studies.accuracy.accuracy_study: the file format, the settings, the errors).

It runs the study's reference and reference check in this process, then every solver setting
``repeats`` times on the runner, each setting a row of the resumable table ``out``/workprecision.csv
(studies.runtime.resumable); with ``out`` it also writes pareto.csv, reference.json and the
work-precision figure (studies.figures.workprecision_figure); without ``out`` the table lives in a scratch
folder removed after, and nothing is drawn.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...models.evaluation.workprecision import Signature
from ..figures.workprecision_figure import plot_workprecision
from ..inputs.arguments import (
    allow_code_problem,
    check,
    either,
    file_problem,
    instance_problem,
)
from ..runtime.interrupts import raise_if_stopped
from ..runtime.output_files import check_out, write_json
from ..runtime.pools import pool
from ..runtime.resumable import RECORD, Table, run_points
from ..runtime.run_options import RunOptions
from ..runtime.tables import write_table
from .accuracy_study import (
    COLUMNS,
    FORMATS,
    TEXT,
    AccuracyStudy,
    Setting,
    load_accuracy_study,
    outcome_row,
    pareto_rows,
    reference_report,
    reference_signature,
    run_setting,
)

if TYPE_CHECKING:
    import pandas as pd

TABLE = "workprecision.csv"
WHERE = "rpdrill.accuracy"
TAKES = ("workers", "dask", "out", "budget", "quiet")  # the run options it has a use for (rpdrill.RunOptions)


class ReferenceFailed(RuntimeError):
    """A reference run of a work-precision study failed: without it no error can be measured."""


@dataclass(frozen=True)
class AccuracyResult:
    """A work-precision study's outcome: its ``table`` (one row a setting: median CPU time, every
    repeat's, the errors against the reference), the Pareto front of each error measure, the
    references' ``report`` (their agreement and whether it is below the smallest error plotted), the
    references' CPU seconds, and the figures written (none without ``out``)."""

    study: AccuracyStudy
    table: pd.DataFrame
    pareto: pd.DataFrame
    report: dict[str, Any]
    reference_cpu_s: dict[str, float]
    figures: list[Path] = field(default_factory=list)
    out: Path | None = None

    @property
    def references_agree(self) -> bool:
        """Whether the references agree better than the smallest error plotted, in every measure."""
        return all(self.report.get("agreement_below_smallest_error", {}).values())


def _reference(study: AccuracyStudy, setting: Setting | None, what: str, cpu: dict[str, float]) -> Signature | None:
    if setting is None:
        return None
    start = time.perf_counter()
    try:
        signature = reference_signature(study, setting)
    except Exception as error:  # noqa: BLE001 - no reference, no study
        raise_if_stopped()  # the run was cut by Ctrl-C or SIGTERM
        raise ReferenceFailed(f"{study.source}: the {what} failed: {type(error).__name__}: {error}") from None
    cpu[what] = time.perf_counter() - start
    return signature


def accuracy(study: AccuracyStudy | str | Path, options: RunOptions | None = None, *,
             allow_code: Sequence[str] | str = (), **run: Any) -> AccuracyResult:
    """Run a work-precision study (or file) as ``options`` say (rpdrill.RunOptions, or its names as keywords:
    ``workers``, ``dask``, ``out``, ``budget``, ``quiet``): into ``out`` (resumable: module doc) or a scratch
    folder; ``allow_code``: the modules of one's own its scene may run (models.definition.own_code).
    InputError or BudgetError before anything runs, ReferenceFailed when a reference run fails."""
    check(WHERE, "study", study,
          either(file_problem, instance_problem(AccuracyStudy, "a work-precision study file's path or its loaded study")))
    options = RunOptions.of(WHERE, options, run, TAKES)
    check(WHERE, "allow_code", allow_code, allow_code_problem)
    folder = None if options.out is None else check_out(options.out, None, RECORD)
    if not isinstance(study, AccuracyStudy):
        study = load_accuracy_study(study, options.budget, allow_code)
    quiet = options.quiet
    wall: dict[str, float] = {}
    reference = _reference(study, study.reference, "reference", wall)
    second = _reference(study, study.reference_check, "reference check", wall)
    spec = study.spec
    with tempfile.TemporaryDirectory(prefix="rpdrill-accuracy-") as scratch, \
            pool(options.dask, options.workers) as runner:
        table = run_points(Table(study, folder or Path(scratch), TABLE, COLUMNS,
                                 lambda p: (study.scene, study.runs[p.index], spec.grid_interval_s, spec.time_limit_s),
                                 run_setting, lambda point, outcome: outcome_row(study, reference, point, outcome),
                                 formats=FORMATS, text=TEXT), runner, quiet)
    front = pareto_rows(table)
    report = reference_report(study, reference, second, table)
    figures = []
    if folder is not None:
        write_table(folder / "pareto.csv", front, {**FORMATS, "error": ".6g"})
        write_json(folder / "reference.json", report)
        title = f"{spec.name}: {spec.blows} blows, reference {study.reference.solver}"
        figures = plot_workprecision(title, table, front, report, folder / f"workprecision.{spec.format}")
    return AccuracyResult(study, table, front, report, wall, figures, folder)
