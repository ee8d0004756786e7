"""The cross-check figure: x_n, bit velocity and rock force of the ODE and the Exudyn model."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from rpdrill.models.results import SimulationResult


def plot_overlay(ode: SimulationResult, exudyn: SimulationResult, title: str, path: Path) -> None:
    """x_n, bit velocity and rock force of both formulations against time."""
    panels = [("bottom_m", 1e3, "borehole bottom x_n [mm]"), ("bit_velocity_m_per_s", 1.0, "bit velocity [m/s]"),
              ("rock_force_n", 1e-3, "rock force [kN]")]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(9, 8))
    for ax, (name, scale, label) in zip(axes, panels):
        ax.plot(ode.time_s, getattr(ode, name) * scale, lw=1.6, label="ODE (Eq. 4, events)")
        ax.plot(exudyn.time_s, getattr(exudyn, name) * scale, lw=0.8, ls="--", label="Exudyn")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best")
    axes[0].set_title(title)
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


