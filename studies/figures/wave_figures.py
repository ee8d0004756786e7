"""The readings along a string of wave rods (models.evaluation.wave_readings) as figures, in the pile-driving
convention (depth down the vertical axis): the stress envelope of the string over the window's blows, and a gauge's
record like a pile-driving analyser's (force and Z v overlaid, the down- and up-going waves below)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...models.evaluation.wave_readings import GaugeRecord, WaveReadings
from .figure_style import OKABE_ITO, figure, save


def plot_envelope(readings: WaveReadings, title: str, path: Path, blows: slice = slice(None)) -> list[Path]:
    """Every rod's largest compression (right) and tension (left, negative) against the depth along the string
    over ``blows``, a rod's sections joined, the rods' joints as lines; the files written."""
    fig = figure(figsize=(5.5, 6.5), layout="constrained")
    ax = fig.subplots()
    for k, (name, envelope) in enumerate(readings.envelopes.items()):
        colour = OKABE_ITO[(k % (len(OKABE_ITO) - 1)) + 1]
        compression = envelope.compression_pa[blows].max(axis=0) / 1e6
        tension = envelope.tension_pa[blows].max(axis=0) / 1e6
        ax.plot(compression, envelope.depth_m, color=colour, lw=1.4, label=name)
        ax.plot(-tension, envelope.depth_m, color=colour, lw=1.4, ls="--")
        ax.axhline(envelope.depth_m[-1], color="0.8", lw=0.6)
    ax.axvline(0.0, color="0.5", lw=0.6)
    ax.invert_yaxis()
    ax.set_xlabel("largest stress over the blows, MPa (compression >0, tension <0, dashed)")
    ax.set_ylabel("depth along the string, m")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    return save(fig, path)


def plot_gauge(gauge: GaugeRecord, title: str, path: Path, period_s: float, blows: int = 1) -> list[Path]:
    """The gauge's last ``blows`` blows: F and Z v overlaid (kN; they part where waves come up), the down- and
    up-going waves below; the files written."""
    start = gauge.time_s[-1] - blows * period_s
    part = gauge.time_s >= start
    t = (gauge.time_s[part] - start) * 1e3
    fig = figure(figsize=(8, 5.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    top.plot(t, gauge.force_n[part] / 1e3, color=OKABE_ITO[5], lw=1.0, label="F")
    top.plot(t, gauge.impedance_velocity_n[part] / 1e3, color=OKABE_ITO[4], lw=1.0, label="Z v")
    bottom.plot(t, gauge.down_n[part] / 1e3, color=OKABE_ITO[3], lw=1.0, label="down (F + Z v) / 2")
    bottom.plot(t, gauge.up_n[part] / 1e3, color=OKABE_ITO[6], lw=1.0, label="up (F - Z v) / 2")
    energy = gauge.energy_j[-1] if len(gauge.energy_j) else np.nan
    top.set_title(f"{title}: gauge {gauge.name} on {gauge.rod} at {gauge.position_m:g} m; "
                  f"last blow ENTHRU {energy:.1f} J", fontsize=9)
    for ax in (top, bottom):
        ax.set_ylabel("kN")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    bottom.set_xlabel("time in the last blows, ms")
    return save(fig, path)
