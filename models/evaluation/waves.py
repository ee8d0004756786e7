"""Stress waves in a segmented rod: arrival times and pulse shapes from a run's force histories.

A rod of length L split into N lumped segments (models.drill.chain) is a discrete wave-guide: its long
waves travel at c = sqrt(E / rho) and its cut-off is omega_max = 2 c N / L, so a pulse of duration
tau is carried faithfully once N >> L / (c tau). The travel time of a pulse from the struck end to
the rock is measured between the instants the impact force and the rock force first reach half of
their peaks.
"""

from __future__ import annotations

import numpy as np

from .results import SimulationResult


def first_crossing_s(time_s: np.ndarray, values: np.ndarray, fraction: float = 0.5) -> float:
    """First time ``values`` reaches ``fraction`` of its peak, linearly interpolated between samples."""
    level = fraction * np.max(values)
    i = int(np.argmax(values >= level))
    if i == 0:
        return float(time_s[0])
    t0, t1, v0, v1 = time_s[i - 1], time_s[i], values[i - 1], values[i]
    return float(t0 + (level - v0) / (v1 - v0) * (t1 - t0))


def travel_time_s(result: SimulationResult) -> float:
    """Half-peak arrival of the rock force minus half-peak arrival of the impact force."""
    return first_crossing_s(result.time_s, result.rock_force_n) - first_crossing_s(result.time_s, result.impact_force_n)


def transmitted_pulse_n(result: SimulationResult, time_s: np.ndarray) -> np.ndarray:
    """The rock force interpolated onto ``time_s`` (to compare runs of different segmentations)."""
    return np.interp(time_s, result.time_s, result.rock_force_n)
