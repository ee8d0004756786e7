"""The paper's figures redrawn from a reproduction's cases (studies.reproduction.paper_reproduction): one panel per metric
against impact frequency, one line per case, each case's main-lobe optimum marked (a filled star; an
open one at a global maximum elsewhere); a flat curve names why in its legend entry, a flat panel on
the panel (studies.scan.flat_curves)."""

from __future__ import annotations

from pathlib import Path

from ..reproduction.paper_reproduction import CaseResult, Figure, Reproduction
from ..scan.flat_curves import why_no_optimum
from .figure_style import figure as new_figure

# Okabe-Ito: distinct for colour-blind readers
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")
# display scale and label of the metrics the figures use
DISPLAY = {
    "penetration_rate_m_per_s": (1e3, "penetration rate [mm/s]"),
    "advance_per_blow_m": (1e3, "borehole-bottom advance per blow [mm]"),
    "bit_velocity_peak_m_per_s": (1.0, "peak bit velocity [m/s]"),
    "collar_velocity_peak_m_per_s": (1.0, "peak collar velocity [m/s]"),
}


def draw_figure(reproduction: Reproduction, results: list[CaseResult], figure: Figure, stem: Path,
                formats: tuple[str, ...] = ("png", "svg")) -> list[Path]:
    """Draw one of the paper's figures into ``stem``.<format>; the paths written."""
    by_label = {r.case.label: r for r in results}
    frequencies = reproduction.frequencies_hz
    fig = new_figure(figsize=(8, 2.8 * len(figure.metrics) + 0.8))
    axes = fig.subplots(len(figure.metrics), 1, sharex=True, squeeze=False)
    for ax, metric in zip(axes[:, 0], figure.metrics, strict=True):
        scale, label = DISPLAY[metric]
        reasons = []
        for k, case in enumerate(figure.cases):
            result, colour = by_label[case], PALETTE[k % len(PALETTE)]
            values = [v * scale for v in result.curves[metric]]
            reasons.append(why_no_optimum(metric, result.curves[metric]))
            ax.plot(frequencies, values, lw=1.2, color=colour,
                    label=case + (f" ({reasons[-1].split(':')[0]})" if reasons[-1] else ""))
            if metric == result.metric:
                optimum = result.optimum
                marks = [(optimum.optimum, optimum.optimum_value, colour)]
                if optimum.global_optimum != optimum.optimum:
                    marks.append((optimum.global_optimum, optimum.best_value, "none"))
                for frequency, value, fill in marks:
                    if frequency is not None:
                        ax.plot(frequency, value * scale, marker="*", ms=13, color=colour, mfc=fill, ls="none")
        if all(reasons) and len(set(reasons)) == 1:  # a flat panel says why on the panel
            ax.text(0.5, 0.5, reasons[0], transform=ax.transAxes, ha="center", va="center", fontsize=10,
                    bbox={"boxstyle": "round", "fc": "white", "ec": "0.6"})
        ax.set_ylabel(label, fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("impact frequency [Hz]")
    axes[0, 0].legend(fontsize=8)
    axes[0, 0].set_title(f"Fig. {figure.number}: {figure.title}", fontsize=10)
    fig.tight_layout()
    written = []
    for fmt in formats:
        path = stem.with_suffix(f".{fmt}")
        fig.savefig(path, dpi=110)
        written.append(path)
    return written
