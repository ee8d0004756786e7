"""The rotation-speed map of one rock (studies.rotation_report): penetration rate over rotation speed
and impact frequency, the optimum ridge of the scan, the model's best speed and the manual's rule."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

SPEED, FREQUENCY, RATE = "rotation.speed_rpm", "impact.frequency_hz", "penetration_rate_m_per_s"


def draw_rotation_map(rows: list[dict[str, str]], path: Path, title: str, best_rpm: Callable[[float], float],
                      manual_rpm: Callable[[float], float]) -> None:
    """Filled contours of the rate (mm/s) with the scan's ridge (best speed at each frequency) and the
    lines n = best_rpm(f), n = manual_rpm(f)."""
    speeds = sorted({float(r[SPEED]) for r in rows})
    frequencies = sorted({float(r[FREQUENCY]) for r in rows})
    rate = np.full((len(frequencies), len(speeds)), np.nan)
    for row in rows:
        rate[frequencies.index(float(row[FREQUENCY])), speeds.index(float(row[SPEED]))] = 1e3 * float(row[RATE])
    fig, ax = plt.subplots(figsize=(8, 6))
    filled = ax.contourf(speeds, frequencies, rate, levels=20)
    fig.colorbar(filled, ax=ax, label="penetration rate (mm/s)")
    ridge = [(speeds[int(np.nanargmax(line))], f) for line, f in zip(rate, frequencies) if np.nanmax(line) > 0]
    if ridge:
        ax.plot(*zip(*ridge), "w-o", lw=2, label="best scanned speed")
    line = np.array(frequencies)
    ax.plot([best_rpm(f) for f in line], line, "r--", lw=1.5, label="model: 60 f w / (pi D)")
    ax.plot([manual_rpm(f) for f in line], line, "k:", lw=1.5, label="manual: 0.741 d 60 f / (pi D)")
    ax.set_xlim(speeds[0], speeds[-1])
    ax.set_xlabel("rotation speed (rpm)")
    ax.set_ylabel("impact frequency (Hz)")
    ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
