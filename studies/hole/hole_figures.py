"""A hole's figure in the pile-driving convention (depth down the vertical axis): the penetration rate, the time to
reach each depth, the largest rod stress (compression and tension) and the energy per blow reaching the rock against
depth, the layers shaded; several holes (a top hammer and a down-the-hole hammer through the same column) on the
same axes."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..figures.figure_style import figure, line_styles, save

PANELS = (("rate_mm_per_s", "penetration rate (mm/s)", 1.0), ("time_s", "time to depth (min)", 1 / 60),
          ("compression_max_mpa", "largest rod stress (MPa)", 1.0),
          ("rock_energy_per_blow_j", "energy reaching the rock per blow (J)", 1.0))


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
        for result, style in zip(results, styles, strict=True):
            rows = result.rows
            kwargs = {**style.kwargs(), "markersize": 3}
            ax.plot(rows[column] * scale, rows["depth_m"], drawstyle="steps-post" if column != "time_s" else "default",
                    label=result.name, **kwargs)
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
