"""Figures of a study drawn from its results table (matplotlib, no screen needed).

Labels, units and scales come from studies.display.catalogue; the title names the scene, its rock and its
impact (what the scan varies left out); each legend entry lists every varied value of its curve
(the plot's ``curves`` axis first).

``curves``: each metric against axis x, one line per combination of the other axes; where the
study's optima (studies.scan.study_optima) run along x, each curve's refined optimum is a star and its
80 % band a bar at 80 % of the peak, otherwise the grid maximum is a star. Failed runs are crosses
on the x axis. ``map``: a metric over two axes as discrete cells, one per scan point (studies.figures.cell_maps:
nothing interpolated; few values are labelled rows); the optimum of each row (refined, as in the
curves) is marked; one panel per combination of the other axes. A plot whose metrics have no finite
value anywhere (every point failed) is not drawn; a panel whose curves (or cells) are all zero says why
on the panel (studies.scan.flat_curves: no crushing), and a flat curve says it in its legend entry.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..display.catalogue import Quantity, describe_scene, metric, quantity
from ..scan.curve_optima import Optimum
from ..scan.flat_curves import why_no_optimum
from ..scan.study import Plot, Study
from ..scan.study_optima import curves, metric_values
from .cell_maps import cell_map, no_result_patch
from .figure_style import figure, line_styles, save

if TYPE_CHECKING:
    import pandas as pd


def curve_label(values: dict[str, Any]) -> str:
    """'$I$ = 160 kN, rock sandstone': every varied value of a curve."""
    parts = []
    for axis, value in values.items():
        q = quantity(axis)
        parts.append(f"{q.name} {value}" if q.categorical or isinstance(value, str) else
                     f"${q.symbol}$ = {q.show_with_unit(value, 3)}")
    return ", ".join(parts)


def title(study: Study, what: str) -> str:
    return f"{study.spec.name}: {what}\n{describe_scene(study.base, study.axes)}"


def _optimum(optima: list[Optimum], name: str, along: str, curve: dict[str, Any]) -> Optimum | None:
    """The optimum of the curve that has the values ``curve`` (a subset of its axes), if one does."""
    found = [o for o in optima if o.metric == name and o.along == along
             and all(o.curve.get(axis) == value for axis, value in curve.items())]
    return found[0] if len(found) == 1 else None


def _mark_optimum(ax: Any, optimum: Optimum | None, x: np.ndarray, y: np.ndarray, xq: Quantity, yq: Quantity,
                  color: str) -> None:
    """The refined optimum and its 80 % band, or the grid maximum of a curve that is not flat."""
    if optimum is not None and optimum.main_lobe is not None:
        peak = yq.display(optimum.main_lobe.peak_value)
        ax.plot(xq.display(optimum.main_lobe.peak), peak, marker="*", ms=13, color=color, mec="white", mew=0.8,
                ls="none")
        ax.plot([xq.display(b) for b in optimum.main_lobe.band_80], [0.8 * peak] * 2, color=color, lw=3, alpha=0.5,
                solid_capstyle="butt")
    elif optimum is None and np.isfinite(y).any() and np.nanmax(y) > np.nanmin(y):
        best = int(np.nanargmax(y))
        ax.plot(x[best], y[best], marker="*", ms=13, color=color, mec="white", mew=0.8, ls="none")


def _curves(plot: Plot, study: Study, table: pd.DataFrame, optima: list[Optimum], path: Path) -> list[Path]:
    xq = quantity(plot.x)
    groups = curves(study, table, plot.x)
    styles = line_styles(len(groups))
    fig = figure(figsize=(9, 2.7 * len(plot.metrics) + 1.2), layout="constrained")
    axes = fig.subplots(len(plot.metrics), 1, sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], plot.metrics):
        yq = metric(name)
        reasons = []
        for style, (curve, members) in zip(styles, groups):
            x = np.array([xq.display(v) for v in members[plot.x].to_numpy(dtype=float)])
            values = list(metric_values(members, name))
            y = np.array([yq.display(v) for v in values])
            leading = {plot.curves: curve[plot.curves]} if plot.curves else {}  # the plot's own axis first
            reasons.append(why_no_optimum(name, values))
            label = curve_label({**leading, **curve}) + (f" ({reasons[-1].split(':')[0]})" if reasons[-1] else "")
            ax.plot(x, y, lw=1.2, ms=4, label=label or None, **style.kwargs())
            _mark_optimum(ax, _optimum(optima, name, plot.x, curve), x, y, xq, yq, style.color)
            failed = x[(members["status"] == "failed").to_numpy()]
            if failed.size:
                ax.plot(failed, np.zeros_like(failed), "x", color=style.color, ms=7, mew=1.5,
                        clip_on=False, transform=ax.get_xaxis_transform())
        if all(reasons) and len(set(reasons)) == 1:  # a flat panel says why on the panel
            ax.text(0.5, 0.5, reasons[0], transform=ax.transAxes, ha="center", va="center", fontsize=10,
                    bbox={"boxstyle": "round", "fc": "white", "ec": "0.6"})
        ax.set_ylabel(yq.label(), fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(xq.label())
    marks = "star: refined optimum, bar: 80 % band" if any(o.along == plot.x for o in optima) else "star: maximum"
    axes[0, 0].set_title(title(study, marks + (", x on the axis: failed run" if (table["status"] == "failed").any()
                                               else "")), fontsize=9)
    if len(groups) > 1:
        fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="outside right upper", fontsize=8)
    return save(fig, path)


def metric_grid(table: pd.DataFrame, x: str, y: str, z: str) -> tuple[list[float], list[float], np.ndarray]:
    """(x values, y values, z[y, x] in SI, NaN where a run failed) of the rows of one map."""
    xs, ys = sorted(set(table[x].to_numpy(dtype=float))), sorted(set(table[y].to_numpy(dtype=float)))
    grid = np.full((len(ys), len(xs)), np.nan)
    for xv, yv, zv in zip(table[x].to_numpy(dtype=float), table[y].to_numpy(dtype=float), metric_values(table, z),
                          strict=True):
        grid[ys.index(yv), xs.index(xv)] = zv
    return xs, ys, grid


def _map(plot: Plot, study: Study, table: pd.DataFrame, optima: list[Optimum], path: Path) -> list[Path]:
    """One panel of cells per combination of the other axes (one panel when there are none); axes zipped
    with x or y change with them, not per panel, and are named in that axis's label."""
    xq, yq, zq = quantity(plot.x), quantity(plot.y), metric(plot.z)
    along = {axis: [a for a in study.zipped_with(axis) if a != axis] for axis in (plot.x, plot.y)}
    others = [a for a in study.axes if a not in (plot.x, plot.y, *along[plot.x], *along[plot.y])]
    panels = [((), table)] if not others else \
        [(key, members) for key, members in table.groupby(others, sort=False)]
    height = 2.2 + 0.5 * min(len(set(study.axes[plot.y])), 12)
    fig = figure(figsize=(9, height * len(panels)), layout="constrained")
    axes = fig.subplots(len(panels), 1, squeeze=False)
    handles: list[Any] = []
    for ax, (key, members) in zip(axes[:, 0], panels):
        xs, ys, z = metric_grid(members, plot.x, plot.y, plot.z)
        position = cell_map(fig, ax, xs, ys, z, xq, yq, zq)
        for axis, set_label, label in ((plot.x, ax.set_xlabel, xq.label()), (plot.y, ax.set_ylabel, yq.label())):
            if along[axis]:
                set_label(f"{label}\nwith {', '.join(quantity(a).name for a in along[axis])}")
        marked, values = [], {float(v): v for v in members[plot.y]}
        fixed = {axis: value.item() if isinstance(value, np.generic) else value
                 for axis, value in zip(others, key, strict=True)}
        for i, y in enumerate(ys):
            optimum = _optimum(optima, plot.z, plot.x, {plot.y: values.get(y), **fixed})
            if optimum is not None and optimum.main_lobe is not None:
                marked.append(position(optimum.main_lobe.peak, y))
            elif optimum is None and np.isfinite(z[i]).any() and np.nanmax(z[i]) > np.nanmin(z[i]):
                marked.append(position(xs[int(np.nanargmax(z[i]))], y))
        if marked:
            (line,) = ax.plot(*zip(*marked), "o", color="white", mec="black", ms=8,
                              label="optimum of each row" + (" (refined)" if optima else ""))
            handles = [line]
        handles += [h for h in no_result_patch(z) if h.get_label() not in {x.get_label() for x in handles}]
        flat = why_no_optimum(plot.z, list(z.ravel()))
        if flat:  # a map of zeros (or of failed runs) says why on the panel
            ax.text(0.5, 0.5, flat, transform=ax.transAxes, ha="center", va="center", fontsize=10,
                    bbox={"boxstyle": "round", "fc": "white", "ec": "0.6"})
        ax.set_title(title(study, zq.name) + (f"\n{curve_label(fixed)}" if fixed else ""), fontsize=9)
    if handles:
        axes[-1, 0].legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(0, -0.12), ncols=2,
                           frameon=False)
    return save(fig, path)


def draw(plot: Plot, study: Study, table: pd.DataFrame, optima: list[Optimum], path: Path) -> list[Path]:
    """Draw one plot of a study into ``path``; the files written."""
    return (_map if plot.kind == "map" else _curves)(plot, study, table, optima, path)
