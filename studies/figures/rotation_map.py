"""The rotation-speed map of one rock (studies.pages.rotation_note): penetration rate over rotation speed
and impact frequency, the optimum ridge of the scan, the model's best speed and the manual's rule."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..display.catalogue import metric, quantity
from .cell_maps import cell_map
from .figure_style import figure, save
from .scan_figures import metric_grid

if TYPE_CHECKING:
    import pandas as pd

SPEED, FREQUENCY, RATE = "rotation.speed_rpm", "impact.frequency_hz", "penetration_rate_m_per_s"


def draw_rotation_map(table: pd.DataFrame, path: Path, title: str, best_rpm: Callable[[float], float],
                      manual_rpm: Callable[[float], float], drilled: float) -> None:
    """The rate (mm/s) of the results ``table`` over speed and frequency with the scan's ridge (best speed at each frequency
    whose best rate reaches ``drilled`` of the map's best) and the lines n = best_rpm(f), n = manual_rpm(f)."""
    fig = figure(figsize=(8, 6), layout="constrained")
    ax = fig.subplots()
    speeds, frequencies, rate = metric_grid(table, SPEED, FREQUENCY, RATE)
    position = cell_map(fig, ax, speeds, frequencies, rate, quantity(SPEED), quantity(FREQUENCY), metric(RATE))
    floor = drilled * np.nanmax(rate) if np.isfinite(rate).any() else 0.0
    ridge = [position(speeds[int(np.nanargmax(line))], f) for line, f in zip(rate, frequencies, strict=True)
             if np.isfinite(line).any() and np.nanmax(line) > np.nanmin(line) and np.nanmax(line) >= floor]
    if ridge:
        ax.plot(*zip(*ridge), "o", color="white", mec="black", ms=7, label="best speed of each frequency (scan)")
    for speed_of, style, label in ((best_rpm, "r--", "model: 60 f w / (pi D)"),
                                   (manual_rpm, "k:", "manual: 0.741 d 60 f / (pi D)")):
        ax.plot(*zip(*(position(speed_of(f), f) for f in frequencies)), style, lw=1.5, label=label)
    ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left")
    save(fig, path)
