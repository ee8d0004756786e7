"""The work-precision figure of an accuracy study: error against CPU time, log-log, one panel per
error measure, one line per solver family, the Pareto front and the references' agreement marked."""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import Any

from ...models.evaluation.workprecision import ERROR_LABELS, ERROR_MEASURES
from ..accuracy.accuracy_study import AccuracyStudy, Row, number
from .figure_style import line_styles, plt, save


def plot_workprecision(study: AccuracyStudy, rows: list[Row], front: list[dict[str, Any]],
                       report: dict[str, Any], path: Path) -> list[Path]:
    """Error against median CPU time, log-log, one panel per measure, one line per family
    (colour-blind-safe styles, studies.figures.figure_style); the files written."""
    fig, axes = plt.subplots(1, len(ERROR_MEASURES), figsize=(6 * len(ERROR_MEASURES), 5.5))
    families: dict[str, list[Row]] = defaultdict(list)
    for row in sorted(rows, key=lambda r: int(r["point"])):
        families[row["family"]].append(row)
    styles = line_styles(len(families))
    for ax, measure in zip(axes, ERROR_MEASURES):
        positive = False  # log axes need a positive value to show (settings equal to the reference have none)
        for style, (label, members) in zip(styles, families.items()):
            pairs = [(number(r["cpu_time_s"]), number(r[measure])) for r in members if r["status"] == "ok"]
            pairs = [(c, e) for c, e in pairs if c > 0 and e > 0 and math.isfinite(e)]
            failed = sum(r["status"] != "ok" for r in members)
            name = label + (f" ({failed} failed)" if failed else "")
            positive |= bool(pairs)
            ax.plot(*(zip(*pairs) if pairs else ([], [])), ms=4, lw=1, label=name, **style.kwargs())
        points = [(number(p["cpu_time_s"]), number(p["error"])) for p in front if p["measure"] == measure]
        points = [(c, e) for c, e in points if c > 0 and e > 0]
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
    fig.suptitle(f"{study.spec.name}: {study.spec.blows} blows, reference {study.reference.solver}")
    fig.tight_layout()
    return save(fig, path, dpi=110)


