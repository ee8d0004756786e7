"""Tornado figures of a one-at-a-time sensitivity study: per scan and metric, the change of the
main-lobe optimum frequency and of its peak value for each parameter at -step and +step, parameters
sorted by their largest effect."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from .figure_style import figure

if TYPE_CHECKING:
    import pandas as pd

# colour-blind-safe pair (Okabe-Ito blue and vermillion) for -step and +step
COLOURS = {-1: "#0072B2", 1: "#D55E00"}


def draw_tornados(table: pd.DataFrame, title: str, out: Path, formats: tuple[str, ...]) -> list[Path]:
    """One figure per (scan, metric) of the one-at-a-time ``table``
    (studies.sensitivity.sensitivity_study.one_at_a_time) with two panels (optimum shift, peak change) in percent."""
    changes, written = table.to_dict("records"), []
    for scan, metric in dict.fromkeys((c["scan"], c["metric"]) for c in changes):
        mine = [c for c in changes if c["scan"] == scan and c["metric"] == metric]
        effect: dict[str, float] = {}
        for c in mine:
            size = max(abs(v) for v in (c["optimum_change"], c["peak_change"]) if math.isfinite(v)) \
                if any(math.isfinite(v) for v in (c["optimum_change"], c["peak_change"])) else 0.0
            effect[c["parameter"]] = max(effect.get(c["parameter"], 0.0), size)
        order = sorted(effect, key=lambda p: effect[p])
        fig = figure(figsize=(11, 0.32 * len(order) + 1.6))
        axes = fig.subplots(1, 2, sharey=True)
        for ax, key, label in zip(axes, ("optimum_change", "peak_change"),
                                  ("optimum frequency change [%]", "peak value change [%]"), strict=True):
            for c in mine:
                sign = 1 if c["change"] > 0 else -1
                value = 100 * c[key] if math.isfinite(c[key]) else 0.0
                ax.barh(order.index(c["parameter"]) + 0.2 * sign, value, height=0.38, color=COLOURS[sign],
                        label=f"{c['change']:+.0%}" if c["parameter"] == order[-1] else None)
            ax.axvline(0.0, color="k", lw=0.8)
            ax.set_xlabel(label)
            ax.grid(axis="x", alpha=0.3)
        axes[0].set_yticks(range(len(order)), order, fontsize=7)
        axes[1].legend(fontsize=8, title="parameter change")
        fig.suptitle(f"{title}: {scan}, {metric}", fontsize=10)
        fig.tight_layout()
        stem = f"tornado_{scan}_{metric}".replace(" ", "_").replace(")", "").replace("(", "").replace("/", "_")
        for fmt in formats:
            path = out / f"{stem}.{fmt}"
            fig.savefig(path, dpi=110)
            written.append(path)
    return written
