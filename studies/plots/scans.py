"""Figures of a study drawn from its results table (matplotlib, no screen needed).

``curves``: each metric against axis x, one curve per combination of the other axes, the
maximum of each curve marked. ``map``: filled contours of a metric over two axes with the
optimum ridge (argmax along x for each y), one panel per combination of the other axes. Flat
curves and rows have no optimum to mark.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rpdrill.studies.study import Plot, Study

Row = dict[str, str]


def _label(text: str) -> str:
    try:
        return f"{float(text):g}"
    except ValueError:
        return text


def _metric(row: Row, name: str) -> float:
    return float(row[name]) if row["status"] == "ok" and row[name] != "" else float("nan")


def _curves(plot: Plot, study: Study, rows: list[Row], path: Path) -> None:
    others = [a for a in study.axes if a != plot.x]
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
    axes[0, 0].set_title(f"{study.spec.name}: maxima marked")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def map_panel(fig: plt.Figure, ax: plt.Axes, rows: list[Row], x: str, y: str, z: str, scale: float = 1.0,
              label: str | None = None, ridge_floor: float = 0.0) -> None:
    """Filled contours of metric ``z`` (times ``scale``) over axes ``x`` and ``y`` of ``rows``, with the
    optimum ridge (the best x for each y whose best reaches ``ridge_floor`` of the map's best)."""
    xs, ys = sorted({float(r[x]) for r in rows}), sorted({float(r[y]) for r in rows})
    grid = np.full((len(ys), len(xs)), np.nan)
    for row in rows:
        grid[ys.index(float(row[y])), xs.index(float(row[x]))] = scale * _metric(row, z)
    filled = ax.contourf(xs, ys, np.ma.masked_invalid(grid), levels=20)
    fig.colorbar(filled, ax=ax, label=label or z)
    floor = ridge_floor * np.nanmax(grid) if np.isfinite(grid).any() else 0.0
    ridge = [(xs[int(np.nanargmax(line))], value) for line, value in zip(grid, ys)
             if np.isfinite(line).any() and np.nanmax(line) > np.nanmin(line) and np.nanmax(line) >= floor]
    if ridge:
        ax.plot(*zip(*ridge), "w-o", lw=2, label="optimum ridge (max along x)")
    ax.set_xlabel(x)
    ax.set_ylabel(y)


def _map(plot: Plot, study: Study, rows: list[Row], path: Path) -> None:
    """One panel per combination of the other axes (one panel when there are none)."""
    others = [a for a in study.axes if a not in (plot.x, plot.y)]
    panels: dict[tuple[str, ...], list[Row]] = defaultdict(list)
    for row in rows:
        panels[tuple(row[a] for a in others)].append(row)
    fig, axes = plt.subplots(1, len(panels), figsize=(8 * len(panels), 6), squeeze=False)
    for ax, (key, members) in zip(axes[0], panels.items()):
        map_panel(fig, ax, members, plot.x, plot.y, plot.z)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
        label = ", ".join(f"{a}={_label(v)}" for a, v in zip(others, key))
        ax.set_title(f"{study.spec.name}: {plot.z}" + (f"\n{label}" if label else ""))
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_name(plot: Plot) -> str:
    if plot.kind == "map":
        return f"map_{plot.z}_over_{plot.x}_{plot.y}".replace(".", "_")
    return f"{'_'.join(plot.metrics) if len(plot.metrics) == 1 else 'metrics'}_vs_{plot.x}".replace(".", "_")


def draw_plots(study: Study, rows: list[Row], out: Path) -> list[Path]:
    """Draw every plot of the study into ``out``; the paths written."""
    paths = []
    for i, plot in enumerate(study.spec.plots):
        path = out / f"{i:02d}_{plot_name(plot)}.{study.spec.format}"
        (_map if plot.kind == "map" else _curves)(plot, study, rows, path)
        paths.append(path)
    return paths
