"""A sensitivity study as a library call: :func:`sensitivity` is ``rpdrill sensitivity`` without its
printing (studies.sensitivity.sensitivity_study: the file format, the points, the analyses).

Its points run through the resumable loop (studies.runtime.resumable: ``out``/results.csv, one row per
scanned variation, and ``out``/study.json); with ``out`` it also writes one_at_a_time.csv, trends.csv,
global.csv (with a ``global`` analysis), summary.json and a tornado figure per scan and metric (PNG
and SVG); without ``out`` the table lives in a scratch folder removed after, and nothing is drawn.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..figures.tornado_figures import draw_tornados
from ..inputs.arguments import (
    allow_code_problem,
    check,
    either,
    file_problem,
    instance_problem,
)
from ..runtime.output_files import check_out, write_json
from ..runtime.pools import pool
from ..runtime.resumable import RECORD, Table, run_points
from ..runtime.run_options import RunOptions
from ..runtime.tables import write_table
from .sensitivity_study import (
    TEXT_COLUMNS,
    TREND_COLUMNS,
    SensitivityStudy,
    columns,
    curve,
    global_indices,
    load_sensitivity,
    number_formats,
    one_at_a_time,
    run_variation,
    summary,
    trends,
)

if TYPE_CHECKING:
    import pandas as pd


WHERE = "rpdrill.sensitivity"
TAKES = ("workers", "dask", "out", "budget", "quiet")  # the run options it has a use for (rpdrill.RunOptions)


@dataclass(frozen=True)
class SensitivityResult:
    """A sensitivity study's outcome (:func:`sensitivity`).

    Parameters
    ----------
    study : SensitivityStudy
        The study, loaded.
    table : pandas.DataFrame
        One row per scanned variation: the optimum and peak of every metric.
    one_at_a_time : pandas.DataFrame
        Each variation's change of the optima and peaks against the nominal scans.
    trends : pandas.DataFrame
        Whether each variation keeps the paper's trends.
    global_indices : pandas.DataFrame
        SALib's indices (empty without a ``global`` analysis).
    summary : dict
        The paper's 3.3 claim measured.
    figures : list of pathlib.Path
        The tornado figures written (none without ``out``).
    out : pathlib.Path or None
        The folder written.

    Attributes
    ----------
    failed : pandas.DataFrame
        The rows of the variations whose every run failed.

    Examples
    --------
    >>> import rpdrill
    >>> found = rpdrill.sensitivity("paper/sensitivity")  # doctest: +SKIP
    >>> found.one_at_a_time.head()  # doctest: +SKIP
    """

    study: SensitivityStudy
    table: pd.DataFrame
    one_at_a_time: pd.DataFrame
    trends: pd.DataFrame
    global_indices: pd.DataFrame
    summary: dict[str, Any]
    figures: list[Path] = field(default_factory=list)
    out: Path | None = None

    @property
    def failed(self) -> pd.DataFrame:
        """The rows of the variations whose every run failed."""
        return self.table[self.table["status"] != "ok"]


def sensitivity(study: SensitivityStudy | str | Path, options: RunOptions | None = None, *,
                allow_code: Sequence[str] | str = (), **run: Any) -> SensitivityResult:
    """How the frequency optima move with each scene parameter: the paper's section 3.3 (``rpdrill sensitivity``).

    Every listed scene number changed by a step one at a time (and, with a ``global`` analysis, SALib's Morris
    or Sobol indices), each variation's frequency scans against the unchanged scene's; resumable in ``out``
    (module doc).

    Parameters
    ----------
    study : SensitivityStudy, str or pathlib.Path
        A sensitivity file, its loaded study, or a shipped one's name (``"paper/sensitivity"``).
    options : RunOptions, optional
        ``workers``, ``dask``, ``out``, ``budget``, ``quiet``; or these names as keywords. Without ``out``, a
        scratch folder removed after, and nothing drawn.
    allow_code : sequence of str or str, default ()
        The modules of one's own its scenes may run (models.definition.own_code).
    **run
        :class:`RunOptions` names.

    Returns
    -------
    SensitivityResult
        The table, the one-at-a-time changes, the trends, the global indices, the summary.

    Raises
    ------
    InputError
        When the file or an option cannot be used, before anything runs.
    BudgetError
        When its runs exceed the budget, before anything runs.

    Examples
    --------
    >>> import rpdrill
    >>> found = rpdrill.sensitivity("paper/sensitivity", out="runs/sensitivity")  # doctest: +SKIP
    >>> found.summary  # doctest: +SKIP
    """
    check(WHERE, "study", study,
          either(file_problem, instance_problem(SensitivityStudy, "a sensitivity file's path or its loaded study")))
    options = RunOptions.of(WHERE, options, run, TAKES)
    check(WHERE, "allow_code", allow_code, allow_code_problem)
    folder = None if options.out is None else check_out(options.out, None, RECORD)
    if not isinstance(study, SensitivityStudy):
        study = load_sensitivity(study, options.budget, allow_code)
    quiet = options.quiet
    with tempfile.TemporaryDirectory(prefix="rpdrill-sensitivity-") as scratch, \
            pool(options.dask, options.workers) as runner:
        table = run_points(Table(study, folder or Path(scratch), "results.csv", columns(study),
                                 lambda point: curve(study, point), run_variation, formats=number_formats(study),
                                 text=TEXT_COLUMNS), runner, quiet)
    changes, kept, indices = one_at_a_time(study, table), trends(study, table), global_indices(study, table)
    result = summary(study, changes, kept)
    figures = []
    if folder is not None:
        write_table(folder / "one_at_a_time.csv", changes)
        write_table(folder / "trends.csv", kept[list(TREND_COLUMNS)])
        if not indices.empty:
            write_table(folder / "global.csv", indices)
        write_json(folder / "summary.json", result)
        figures = draw_tornados(changes, study.spec.name, folder, ("png", "svg"))
    return SensitivityResult(study, table, changes, kept, indices, result, figures, folder)
