"""A hole's figure in the pile-driving convention (depth down the vertical axis): the penetration rate, the time to
reach each depth (a rod change a horizontal step: the clock runs, the depth stays), the largest rod stress (compression and tension) and the energy per blow reaching the rock against
depth, the layers shaded; several holes (a top hammer and a down-the-hole hammer through the same column) on the
same axes."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..figures.figure_style import figure, line_styles, save

PANELS = (("rate_mm_per_s", "penetration rate (mm/s)", 1.0), ("time_s", "time to depth (min)", 1 / 60),
          ("compression_max_mpa", "largest rod stress (MPa)", 1.0),
          ("rock_energy_per_blow_j", "energy reaching the rock per blow (J)", 1.0))


def time_with_rod_changes(rows: Any, rod_change_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The time-depth curve with each rod change drawn where it happens: at the depth of the row before the rows
    where ``rods`` grows, the clock runs on by ``rod_change_s`` per rod added while the depth stays (a horizontal
    step), then drilling resumes to the next row."""
    time_s, depth_m, rods = (rows[c].to_numpy(dtype=float) for c in ("time_s", "depth_m", "rods"))
    times, depths = [time_s[0]], [depth_m[0]]
    for i in range(1, len(time_s)):
        if rods[i] > rods[i - 1]:
            times.append(time_s[i - 1] + (rods[i] - rods[i - 1]) * rod_change_s)
            depths.append(depth_m[i - 1])
        times.append(time_s[i])
        depths.append(depth_m[i])
    return np.array(times), np.array(depths)


def plot_hole(results: Sequence[Any], holes: Sequence[Any], path: Path) -> list[Path]:
    """One figure of ``results`` (studies.hole.hole_run.HoleResult, one line each) into ``path`` (and its SVG); the
    layers of the first hole shaded."""
    fig = figure(figsize=(13, 5.5))
    axes = fig.subplots(1, len(PANELS), sharey=True)
    styles = line_styles(len(results))
    for ax, (column, label, scale) in zip(axes, PANELS, strict=True):
        top = 0.0
        for i, layer in enumerate(holes[0].spec.layers):
            ax.axhspan(top, layer.to_m, color="0.93" if i % 2 else "0.85", zorder=0)
            if ax is axes[0]:
                ax.text(0.02, (top + layer.to_m) / 2, layer.rock.get("name", f"layer {i + 1}"),
                        transform=ax.get_yaxis_transform(), va="center", fontsize=8, color="0.3")
            top = layer.to_m
        for result, hole, style in zip(results, holes, styles, strict=True):
            rows = result.rows
            kwargs = {**style.kwargs(), "markersize": 3}
            if column == "time_s":
                time_s, depth_m = time_with_rod_changes(rows, hole.spec.rod_change_s)
                ax.plot(time_s * scale, depth_m, label=result.name, **kwargs)
            else:
                ax.plot(rows[column] * scale, rows["depth_m"], drawstyle="steps-post", label=result.name, **kwargs)
            if column == "compression_max_mpa":
                ax.plot(rows["tension_max_mpa"], rows["depth_m"], drawstyle="steps-post", alpha=0.6,
                        **{**kwargs, "linestyle": ":"}, label=f"{result.name} (tension)")
        ax.set_xlabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("depth (m)")
    axes[0].set_ylim(max(h.spec.depth_m for h in holes), 0.0)
    axes[2].legend(fontsize=7, loc="lower right")
    fig.suptitle(" vs ".join(result.name for result in results))
    return save(fig, path)
