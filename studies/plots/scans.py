"""Figures of a study drawn from its results table (matplotlib, no screen needed).

``curves``: each metric against axis x, one curve per combination of the other axes, the
maximum of each curve marked. ``map``: filled contours of a metric over two axes with the
optimum ridge (argmax along x for each y). Flat curves and rows have no optimum to mark.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from rpdrill.studies.study import Plot, Study

Row = dict[str, str]


def _pyplot() -> ModuleType:
    """matplotlib's pyplot without a screen, imported when a plot is drawn (by a worker), not when a
    command starts."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _label(text: str) -> str:
    try:
        return f"{float(text):g}"
    except ValueError:
        return text


def _metric(row: Row, name: str) -> float:
    return float(row[name]) if row["status"] == "ok" and row[name] != "" else float("nan")


def _curves(plot: Plot, axes_values: dict[str, list[Any]], name: str, rows: list[Row], path: Path) -> None:
    plt = _pyplot()
    others = [a for a in axes_values if a != plot.x]
    label_axes = [plot.curves] if plot.curves else others
    groups: dict[tuple[str, ...], list[Row]] = defaultdict(list)
    for row in rows:
        groups[tuple(row[a] for a in others)].append(row)
    fig, axes = plt.subplots(len(plot.metrics), 1, sharex=True, figsize=(8, 2.6 * len(plot.metrics) + 1),
                             squeeze=False)
    for ax, metric in zip(axes[:, 0], plot.metrics):
        for key, members in groups.items():
            members = sorted(members, key=lambda r: float(r[plot.x]))
            x = np.array([float(r[plot.x]) for r in members])
            y = np.array([_metric(r, metric) for r in members])
            label = ", ".join(f"{a}={_label(dict(zip(others, key))[a])}" for a in label_axes)
            (line,) = ax.plot(x, y, marker=".", lw=1, label=label or None)
            if np.isfinite(y).any() and np.nanmax(y) > np.nanmin(y):  # a flat curve has no optimum
                best = int(np.nanargmax(y))
                ax.plot(x[best], y[best], marker="*", ms=12, color=line.get_color())
                ax.annotate(f"{x[best]:.4g}", (x[best], y[best]), textcoords="offset points", xytext=(4, 4),
                            fontsize=8, color=line.get_color())
        ax.set_ylabel(metric, fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(plot.x)
    if len(groups) > 1:
        axes[0, 0].legend(fontsize=7)
    axes[0, 0].set_title(f"{name}: maxima marked")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _map(plot: Plot, axes_values: dict[str, list[Any]], name: str, rows: list[Row], path: Path) -> None:
    plt = _pyplot()
    xs, ys = sorted(set(axes_values[plot.x])), sorted(set(axes_values[plot.y]))
    z = np.full((len(ys), len(xs)), np.nan)
    for row in rows:
        z[ys.index(float(row[plot.y])), xs.index(float(row[plot.x]))] = _metric(row, plot.z)
    fig, ax = plt.subplots(figsize=(8, 6))
    filled = ax.contourf(xs, ys, np.ma.masked_invalid(z), levels=20)
    fig.colorbar(filled, ax=ax, label=plot.z)
    ridge = [(xs[int(np.nanargmax(line))], y) for line, y in zip(z, ys)
             if np.isfinite(line).any() and np.nanmax(line) > np.nanmin(line)]
    if ridge:
        ax.plot(*zip(*ridge), "w-o", lw=2, label="optimum ridge (max along x)")
        ax.legend(fontsize=8)
    ax.set_xlabel(plot.x)
    ax.set_ylabel(plot.y)
    ax.set_title(f"{name}: {plot.z}")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_name(plot: Plot) -> str:
    if plot.kind == "map":
        return f"map_{plot.z}_over_{plot.x}_{plot.y}".replace(".", "_")
    return f"{'_'.join(plot.metrics) if len(plot.metrics) == 1 else 'metrics'}_vs_{plot.x}".replace(".", "_")


PlotTask = tuple[Plot, dict[str, list[Any]], str, list[Row], Path]  # plot, scan axes, study name, rows, file


def plot_tasks(study: Study, rows: list[Row], out: Path) -> list[PlotTask]:
    """One task per plot of the study: what :func:`draw_plot` needs (no prepared points: small to send)."""
    return [(plot, study.axes, study.spec.name, rows, out / f"{i:02d}_{plot_name(plot)}.{study.spec.format}")
            for i, plot in enumerate(study.spec.plots)]


def draw_plot(task: PlotTask) -> Path:
    """Worker: draw one plot of a study's results; the path written."""
    plot, axes, name, rows, path = task
    (_map if plot.kind == "map" else _curves)(plot, axes, name, rows, path)
    return path
