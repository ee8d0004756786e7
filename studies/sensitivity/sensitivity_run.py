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
    check_run_options,
    either,
    file_problem,
    instance_problem,
)
from ..runtime.budgets import DEFAULT_BUDGET, Budget
from ..runtime.output_files import check_out, write_json
from ..runtime.pools import pool
from ..runtime.resumable import RECORD, Table, run_points
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


def sensitivity(study: SensitivityStudy | str | Path, workers: int | None = None, out: str | Path | None = None,
                dask: str | None = None, budget: Budget = DEFAULT_BUDGET, quiet: bool = True,
                allow_code: Sequence[str] | str = ()) -> SensitivityResult:
    """Run a sensitivity study (or file) on ``workers`` processes (default all cores; 1: in this process) or
    a Dask cluster (``dask``: an address, "" a LocalCluster), into ``out`` (resumable: module doc) or a
    scratch folder. InputError or BudgetError before anything runs; ``quiet``: no progress bar; ``allow_code``:
    the modules of one's own its scenes may run (models.definition.own_code)."""
    check(WHERE, "study", study,
          either(file_problem, instance_problem(SensitivityStudy, "a sensitivity file's path or its loaded study")))
    check_run_options(WHERE, workers, out, dask, quiet)
    check(WHERE, "budget", budget, instance_problem(Budget, "a rpdrill.Budget"))
    check(WHERE, "allow_code", allow_code, allow_code_problem)
    folder = None if out is None else check_out(out, None, RECORD)
    if not isinstance(study, SensitivityStudy):
        study = load_sensitivity(study, budget, allow_code)
    with tempfile.TemporaryDirectory(prefix="rpdrill-sensitivity-") as scratch, pool(dask, workers) as runner:
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
