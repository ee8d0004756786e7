"""Figures of single runs (matplotlib, no screen needed)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def plot_timeseries(columns: dict[str, np.ndarray], title: str, path: Path) -> None:
    """Bit velocity, borehole bottom x_n, rock force and impact force against time (those recorded)."""
    t = columns["time_s"]
    panels = [
        ("bit_velocity_m_per_s", 1.0, "bit velocity [m/s]"),
        ("borehole_bottom_m", 1e3, "borehole bottom x_n [mm]"),
        ("rock_force_n", 1e-3, "rock force [kN]"),
        ("impact_force_n", 1e-3, "impact force [kN]"),
    ]
    panels = [panel for panel in panels if panel[0] in columns]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(8, 2 * len(panels) + 0.5), squeeze=False)
    axes = axes[:, 0]
    for ax, (name, scale, label) in zip(axes, panels):
        ax.plot(t, columns[name] * scale, lw=0.8)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
