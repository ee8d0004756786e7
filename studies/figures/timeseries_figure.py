"""The time histories of one run: the whole run beside a zoom on its last few blows (at tens of blows
per second the whole run is a solid band; the zoom shows the blows themselves). Labels and units
from studies.display.catalogue; the title names the scene, its rock and its impact."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...models.definition.scene import Scene
from ..display.catalogue import describe_scene, series
from .figure_style import OKABE_ITO, figure, save

PANELS = ("bit_velocity_m_per_s", "borehole_bottom_m", "rock_force_n", "impact_force_n")
ZOOM_BLOWS = 3


def plot_timeseries(columns: dict[str, np.ndarray], scene: Scene, path: Path) -> list[Path]:
    """Bit velocity, borehole bottom x_n, rock force and impact force (those recorded) and the histories
    the scene's outputs ask for besides (a piston's contact force) against time: the whole run (left) and
    its last ZOOM_BLOWS impact periods (right). The files written."""
    t = columns["time_s"]
    asked = scene.outputs.timeseries if scene.outputs is not None else []
    panels = [name for name in (*PANELS, *asked) if name in columns]
    panels = list(dict.fromkeys(panels)) or [next(name for name in columns if name != "time_s")]
    zoom = t >= t[-1] - ZOOM_BLOWS * scene.impact.period_s
    time = series("time_s")
    fig = figure(figsize=(11, 2 * len(panels) + 0.8), layout="constrained")
    axes = fig.subplots(len(panels), 2, sharex="col", squeeze=False, width_ratios=(3, 2))
    for row, name in zip(axes, panels):
        quantity = series(name)
        for ax, part in zip(row, (slice(None), zoom)):
            ax.plot(time.display(t[part]), quantity.display(columns[name][part]), lw=0.8, color=OKABE_ITO[4])
            ax.grid(alpha=0.3)
        row[0].set_ylabel(quantity.label(), fontsize=9)
    axes[0, 0].set_title("whole run", fontsize=9)
    axes[0, 1].set_title(f"last {ZOOM_BLOWS} blows", fontsize=9)
    for ax in axes[-1]:
        ax.set_xlabel(time.label())
    fig.suptitle(describe_scene(scene), fontsize=10)
    return save(fig, path)
