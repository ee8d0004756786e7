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
    """A work-precision study's outcome (:func:`accuracy`).

    Parameters
    ----------
    study : AccuracyStudy
        The study, loaded.
    table : pandas.DataFrame
        One row a solver setting: its median CPU time, every repeat's, the errors against the reference.
    pareto : pandas.DataFrame
        The Pareto front of each error measure.
    report : dict
        The references' agreement, and whether it is below the smallest error plotted.
    reference_cpu_s : dict of str to float
        The references' CPU seconds.
    figures : list of pathlib.Path
        The figures written (none without ``out``).
    out : pathlib.Path or None
        The folder written.

    Attributes
    ----------
    references_agree : bool
        Whether the references agree better than the smallest error plotted, in every measure.

    Examples
    --------
    >>> import rpdrill
    >>> study = rpdrill.accuracy("accuracy_studies/paper_base")  # doctest: +SKIP
    >>> study.table.head()  # doctest: +SKIP
    """

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
    """A work-precision study: the error against CPU time of every solver setting, and its Pareto front.

    ``rpdrill accuracy`` as a library call (module doc; docs/accuracy.md): the study's reference and reference
    check run in this process, then every setting ``repeats`` times; resumable in ``out``.

    Parameters
    ----------
    study : AccuracyStudy, str or pathlib.Path
        A work-precision study file, its loaded study, or a shipped one's name
        (``"accuracy_studies/paper_base"``).
    options : RunOptions, optional
        ``workers``, ``dask``, ``out``, ``budget``, ``quiet``; or these names as keywords. Without ``out``, a
        scratch folder removed after, and nothing drawn.
    allow_code : sequence of str or str, default ()
        The modules of one's own its scene may run (models.definition.own_code).
    **run
        :class:`RunOptions` names.

    Returns
    -------
    AccuracyResult
        The table, the Pareto front, the references' report.

    Raises
    ------
    InputError
        When the file or an option cannot be used, before anything runs.
    BudgetError
        When its runs exceed the budget, before anything runs.
    ReferenceFailed
        When a reference run fails.

    Examples
    --------
    >>> import rpdrill
    >>> study = rpdrill.accuracy("accuracy_studies/paper_base", out="runs/accuracy")  # doctest: +SKIP
    >>> study.references_agree, study.pareto  # doctest: +SKIP
    """
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
