"""The rotation-speed map of one rock (studies.rotation_report): penetration rate over rotation speed
and impact frequency, the optimum ridge of the scan, the model's best speed and the manual's rule."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rpdrill.studies.plots.scans import map_panel

SPEED, FREQUENCY, RATE = "rotation.speed_rpm", "impact.frequency_hz", "penetration_rate_m_per_s"


def draw_rotation_map(rows: list[dict[str, str]], path: Path, title: str, best_rpm: Callable[[float], float],
                      manual_rpm: Callable[[float], float], drilled: float) -> None:
    """The rate (mm/s) over speed and frequency with the scan's ridge (best speed at each frequency
    whose best rate reaches ``drilled`` of the map's best) and the lines n = best_rpm(f), n = manual_rpm(f)."""
    fig, ax = plt.subplots(figsize=(8, 6))
    map_panel(fig, ax, rows, SPEED, FREQUENCY, RATE, scale=1e3, label="penetration rate (mm/s)", ridge_floor=drilled)
    frequencies = np.array(sorted({float(r[FREQUENCY]) for r in rows}))
    ax.plot([best_rpm(f) for f in frequencies], frequencies, "r--", lw=1.5, label="model: 60 f w / (pi D)")
    ax.plot([manual_rpm(f) for f in frequencies], frequencies, "k:", lw=1.5, label="manual: 0.741 d 60 f / (pi D)")
    speeds = sorted({float(r[SPEED]) for r in rows})
    ax.set_xlim(speeds[0], speeds[-1])
    ax.set_xlabel("rotation speed (rpm)")
    ax.set_ylabel("impact frequency (Hz)")
    ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
