"""The cross-check figure: x_n, bit velocity and rock force of the ODE and the Exudyn model."""

from __future__ import annotations

from pathlib import Path

from ...models.evaluation.results import SimulationResult
from ..display.catalogue import series
from .figure_style import OKABE_ITO, figure, save

# result attribute -> time-history column (studies.display.catalogue)
PANELS = {"bottom_m": "borehole_bottom_m", "bit_velocity_m_per_s": "bit_velocity_m_per_s", "rock_force_n": "rock_force_n"}


def plot_overlay(ode: SimulationResult, exudyn: SimulationResult, title: str, path: Path) -> list[Path]:
    """x_n, bit velocity and rock force of both formulations against time; the files written."""
    fig = figure(figsize=(9, 8))
    axes = fig.subplots(len(PANELS), 1, sharex=True)
    time = series("time_s")
    for ax, (name, column) in zip(axes, PANELS.items()):
        quantity = series(column)
        ax.plot(time.display(ode.time_s), quantity.display(getattr(ode, name)), lw=1.6, color=OKABE_ITO[2],
                label="ODE (Eq. 4, events)")
        ax.plot(time.display(exudyn.time_s), quantity.display(getattr(exudyn, name)), lw=0.8, ls="--",
                color=OKABE_ITO[0], label="Exudyn")
        ax.set_ylabel(quantity.label())
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best")
    axes[0].set_title(title)
    axes[-1].set_xlabel(time.label())
    fig.tight_layout()
    return save(fig, path)


