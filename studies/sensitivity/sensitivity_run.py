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
    """A sensitivity study's outcome: its results ``table`` (one row per scanned variation: optimum and peak
    of every metric), the one-at-a-time changes against the nominal scans, whether each variation keeps
    the trends, the global indices (empty without a ``global`` analysis), the ``summary`` (the paper's
    3.3 claim measured) and the figures written (none without ``out``)."""

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
    """Run a sensitivity study (or file) as ``options`` say (rpdrill.RunOptions, or its names as keywords:
    ``workers``, ``dask``, ``out``, ``budget``, ``quiet``): into ``out`` (resumable: module doc) or a scratch
    folder; ``allow_code``: the modules of one's own its scenes may run (models.definition.own_code).
    InputError or BudgetError before anything runs."""
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
