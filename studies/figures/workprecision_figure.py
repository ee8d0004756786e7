"""The work-precision figure of an accuracy study: error against CPU time, log-log, one panel per
error measure, one line per solver family, the Pareto front and the references' agreement marked."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ...models.evaluation.workprecision import ERROR_LABELS, ERROR_MEASURES
from .figure_style import figure, line_styles, save

if TYPE_CHECKING:
    import pandas as pd


def plot_workprecision(title: str, table: pd.DataFrame, front: pd.DataFrame, report: dict[str, Any],
                       path: Path) -> list[Path]:
    """Error against median CPU time (the study's ``table``: studies.accuracy.accuracy_study), log-log, one panel
    per measure, one line per family (colour-blind-safe styles, studies.figures.figure_style), the Pareto
    ``front`` and the references' agreement of the ``report``; the files written."""
    fig = figure(figsize=(6 * len(ERROR_MEASURES), 5.5))
    axes = fig.subplots(1, len(ERROR_MEASURES))
    families = list(table.groupby("family", sort=False))
    styles = line_styles(len(families))
    for ax, measure in zip(axes, ERROR_MEASURES):
        positive = False  # log axes need a positive value to show (settings equal to the reference have none)
        for style, (label, members) in zip(styles, families):
            ok = members[members["status"] == "ok"]
            pairs = [(c, e) for c, e in zip(ok["cpu_time_s"].astype(float), ok[measure].astype(float))
                     if c > 0 and e > 0 and math.isfinite(e)]
            failed = int((members["status"] != "ok").sum())
            name = label + (f" ({failed} failed)" if failed else "")
            positive |= bool(pairs)
            ax.plot(*(zip(*pairs) if pairs else ([], [])), ms=4, lw=1, label=name, **style.kwargs())
        mine = front[front["measure"] == measure]
        points = [(c, e) for c, e in zip(mine["cpu_time_s"].astype(float), mine["error"].astype(float))
                  if c > 0 and e > 0]
        if points:
            ax.step(*zip(*points), where="post", color="k", ls="--", lw=1, label="Pareto front")
            ax.plot(*zip(*points), "o", mfc="none", mec="k", ms=9)
        agreement = report.get("agreement", {}).get(measure)
        if agreement and agreement > 0:
            ax.axhline(agreement, color="gray", ls=":", lw=1, label="references' agreement")
        if positive:
            ax.set_xscale("log")
            ax.set_yscale("log")
        else:
            ax.text(0.5, 0.5, "no error above 0", transform=ax.transAxes, ha="center")
        ax.set_xlabel("CPU time [s] (median of repeats)")
        ax.set_ylabel(f"{ERROR_LABELS[measure]} [-]")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(title)
    fig.tight_layout()
    return save(fig, path, dpi=110)


