"""The bifurcation diagram of a drill (studies.scan.bifurcation_diagram): the advance and the peak rock force of
every blow of the settled response against the scan axis. Grey dots: the last blows of long time runs (the
brute-force diagram). Lines: the orbits followed from both ends of the axis, solid where stable, coloured by
their period (a period-n orbit draws its n blows); dashed: the period-1 orbit where it is unstable (never the
rate a drill shows). Crosses: points where no periodic orbit was found (the time run's last blows)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..display.catalogue import parameter
from ..scan.bifurcation_diagram import BlowFigures, Diagram
from .figure_style import OKABE_ITO, figure, save

PANELS = (("advance_m", 1e6, "advance per blow [um]"), ("peak_rock_force_n", 1e-3, "peak rock force per blow [kN]"))


def _period(figure: BlowFigures) -> int | None:
    return int(figure.regime.rpartition("-")[2]) if figure.regime.startswith("period-") else None


def plot_bifurcation(diagram: Diagram, path: Path, title: str) -> list[Path]:
    """The diagram's figure (module doc) into ``path`` (and an SVG beside it); the files written."""
    fig = figure(figsize=(9, 7.5), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    axis = parameter(diagram.axis)
    for ax, (name, factor, label) in zip(axes, PANELS, strict=True):
        dots = [(axis.display(f.value), v * factor) for f in diagram.brute_force for v in getattr(f, name)]
        ax.plot(*zip(*dots), ".", color="0.6", ms=2.5, label="time runs: last blows (brute force)")
        one = diagram.period_one
        values = np.array([axis.display(f.value) for f in one])
        level = np.array([getattr(f, name)[0] * factor for f in one])
        stable = np.array([f.stable for f in one])
        if len(one):
            ax.plot(values, np.where(stable, level, np.nan), "-", color=OKABE_ITO[4], lw=1.6,
                    label="period-1 orbit, stable")
            if not stable.all():
                ax.plot(values, np.where(~stable, level, np.nan), "--", color=OKABE_ITO[4], lw=1.2,
                        label="period-1 orbit, unstable (not the rate)")
        shown: set[str] = set()
        for direction, marker, figures in (("up", "o", diagram.up), ("down", "s", diagram.down)):
            for blow in figures:
                n = _period(blow)
                if n is None:
                    key = f"no periodic orbit found ({direction})"
                    ax.plot([axis.display(blow.value)] * len(getattr(blow, name)), np.array(getattr(blow, name)) * factor,
                            "x", color=OKABE_ITO[5], ms=4, label=None if key in shown else key)
                elif n > 1:
                    key = f"period-{n} orbit ({direction})"
                    ax.plot([axis.display(blow.value)] * n, np.array(getattr(blow, name)) * factor, marker,
                            color=OKABE_ITO[(n % 5) + 1], mfc="none", ms=5, label=None if key in shown else key)
                else:
                    key = f"period-1 orbit ({direction})"
                    ax.plot([axis.display(blow.value)], [getattr(blow, name)[0] * factor], marker,
                            color=OKABE_ITO[4], mfc="none", ms=3, label=None if key in shown else key)
                shown.add(key)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, loc="best")
    axes[-1].set_xlabel(axis.label())
    axes[0].set_title(title, fontsize=10)
    return save(fig, path)
