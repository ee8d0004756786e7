"""The figures of ``rpdrill advise`` for one rock: the metric along each operating parameter through
the optimum (80 % band shaded), and the feed x frequency map (discrete cells, the best feed at
each frequency, the thrust limit and the optimum marked; studies.advice.advice_search)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..display.catalogue import metric, parameter
from ..figures.cell_maps import cell_map, no_result_patch
from ..figures.figure_style import OKABE_ITO, figure, save
from .advice_search import FEED, FREQUENCY, Advice


def _title(advice: Advice, what: str) -> str:
    return f"{what}\n{advice.description}"


def plot_curves(advice: Advice, path: Path) -> list[Path]:
    """One panel per parameter: the metric across its bounds, the others at the optimum."""
    y = metric(advice.metric)
    fig = figure(figsize=(4.2 * len(advice.slices), 3.8), layout="constrained")
    axes = fig.subplots(1, len(advice.slices), sharey=True, squeeze=False)
    for ax, (path_, curve) in zip(axes[0], advice.slices.items()):
        x = parameter(path_)
        ax.axvspan(*x.display(np.array(curve["band_80"])), color=OKABE_ITO[2], alpha=0.25,
                   label=f"{y.name} >= 80 % of the optimum")
        ax.plot(x.display(np.array(curve["values"])), y.display(np.array(curve["metric"])), marker="o", ms=3,
                color=OKABE_ITO[4])
        ax.plot(x.display(advice.best[path_]), y.display(advice.best_value), "*", ms=15, color=OKABE_ITO[5],
                mec="white", label="optimum")
        ax.set_xlabel(x.label())
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel(y.label())
    axes[0, 0].legend(fontsize=8, loc="best")
    best = ", ".join(f"{parameter(p).name} {parameter(p).show_with_unit(v)}" for p, v in advice.best.items())
    fig.suptitle(_title(advice, f"{y.name} {y.show_with_unit(advice.best_value)} at {best}"), fontsize=9)
    return save(fig, path)


def plot_feed_map(advice: Advice, path: Path) -> list[Path]:
    """The metric over feed force and impact frequency; the best feed at each frequency and the optimum."""
    grid = advice.feed_map
    frequencies, feeds, z = grid[FREQUENCY], grid[FEED], np.array(grid["metric"], dtype=float)
    fig = figure(figsize=(9, 6), layout="constrained")
    ax = fig.subplots()
    position = cell_map(fig, ax, frequencies, feeds, z, parameter(FREQUENCY), parameter(FEED), metric(advice.metric))
    best_feed = [position(f, feeds[int(np.argmax(column))]) for f, column in zip(frequencies, z.T, strict=True)
                 if np.any(column > 0)]
    handles = no_result_patch(z, "not run (beyond the thrust limit) or failed")
    limit = np.array(grid["limit_feed_n"])
    if np.any(limit < feeds[-1]):
        handles.append(ax.plot(*zip(*(position(f, min(max(v, feeds[0]), feeds[-1])) for f, v in zip(frequencies, limit))),
                               "--", color=OKABE_ITO[5], lw=2,
                               label=f"thrust limit: feed + f J = {advice.max_thrust_ratio:g} F_th")[0])
    if best_feed:
        handles.append(ax.plot(*zip(*best_feed), "o", color="white", mec="black", ms=7,
                               label="best feed force at each frequency")[0])
    handles.append(ax.plot(*position(advice.best[FREQUENCY], advice.best[FEED]), "*", ms=16, color=OKABE_ITO[5],
                           mec="white", label="optimum (search)")[0])
    ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(0, -0.1), ncols=3, frameon=False)
    others = [p for p in advice.best if p not in (FREQUENCY, FEED)]
    at = "; " + ", ".join(f"{parameter(p).name} {parameter(p).show_with_unit(advice.best[p])}" for p in others) \
        if others else ""
    ax.set_title(_title(advice, f"{metric(advice.metric).name} over feed force and impact frequency{at}"), fontsize=9)
    return save(fig, path)
