"""A study's plots as tasks of a runner: which plots have a result, their files, and handing them to
the runner's workers, which draw them (studies.figures.scan_figures). Nothing here imports matplotlib, so a
command whose workers draw its plots does not load it in its own process."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..runtime.pools import Runner, sequential
from ..scan.curve_optima import Optimum
from ..scan.study import Plot, Study
from ..scan.study_optima import metric_values

if TYPE_CHECKING:
    import pandas as pd

PlotTask = tuple[Plot, Study, "pd.DataFrame", list[Optimum], Path]


def plot_name(plot: Plot) -> str:
    if plot.kind == "map":
        return f"map_{plot.z}_over_{plot.x}_{plot.y}".replace(".", "_")
    return f"{'_'.join(plot.metrics) if len(plot.metrics) == 1 else 'metrics'}_vs_{plot.x}".replace(".", "_")


def draw_plot(task: PlotTask) -> list[Path]:
    """Worker: draw one plot of a study into its path (studies.figures.scan_figures, matplotlib loaded here, in
    the worker); the files written."""
    from .scan_figures import draw

    return draw(*task)


def plot_tasks(study: Study, table: pd.DataFrame, optima: list[Optimum], out: Path) -> tuple[list[PlotTask], list[str]]:
    """(A :func:`draw_plot` task per plot of the study that has a result, into ``out``; the names of the
    plots left out because none of their metrics has a finite value)."""
    tasks, skipped = [], []
    for i, plot in enumerate(study.spec.plots):
        name = f"{i:02d}_{plot_name(plot)}"
        if any(np.isfinite(metric_values(table, m)).any() for m in plot.metrics):
            tasks.append((plot, study, table, optima, out / f"{name}.{study.spec.format}"))
        else:
            skipped.append(name)
    return tasks, skipped


def start_plots(study: Study, table: pd.DataFrame, optima: list[Optimum], out: Path,
                runner: Runner = sequential) -> Callable[[], tuple[list[Path], list[str]]]:
    """Hand every plot of the study that has a result to ``runner`` now, one plot per task (a pool's
    workers start drawing them at once, side by side, while this process goes on), and return the call
    that waits for them: (the files written, the names of the plots left out because none of their
    metrics has a finite value). With the sequential runner the plots are drawn by that call."""
    tasks, skipped = plot_tasks(study, table, optima, out)
    pending = runner(draw_plot, tasks) if tasks else iter(())
    return lambda: (sorted(path for batch in pending for paths in batch for path in paths), skipped)
