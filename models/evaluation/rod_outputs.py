"""What the rods carry: the stress at each rod's ends (the sections of its joints), per blow its largest
compression and tension there and the energy through them, and the rock's energy per blow.

A rod is any body with a rod geometry, carried as waves or lumped. Its end's axial force P (positive in
compression) is

* a wave rod's: from its waves, P = sigma Z (outgoing - incoming) (models.drill.wave_rod), and its per-blow
  figures integrated by the formulation over every step of the characteristics (models.waves.record);
* a lumped rod's: the sum of what acts on that end, the connectors joined there (their force, positive
  in compression), at the top the pulse or the piston's contact on the impact body, at the bottom the
  rock on the rock body; per blow from the stored samples (every solver step when an output needs it).

Stress = P / A (compression positive). The energy through an end is int P v dt, positive along +x
(into the rock): what enters the rod at its top, what leaves it at its bottom. The rock's energy per
blow is int F_r v_bit dt over the blow (its net work: what the rock took less what it gave back).
Module reads a run's result by duck typing (models.evaluation.results holds the type).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..drill.wave_rod import BOTTOM, TOP
from .parts import link_series


@dataclass(frozen=True)
class RodEnd:
    """One end of one rod: its compression (N) and velocity (m/s) at the result's samples."""

    rod: str
    end: str
    area_m2: float
    compression_n: np.ndarray
    velocity_m_per_s: np.ndarray


def rods(scene: Any) -> list[str]:
    """The drill string's rods (bodies with a rod geometry), in the scene's order."""
    return [name for name, body in scene.drill_string.bodies.items() if body.is_rod]


def rod_end(result: Any, rod: str, end: str) -> RodEnd:
    """The rod's end ``end`` of ``result`` (module doc)."""
    body = result.scene.drill_string.bodies[rod]
    chain = result.chain
    first, last = chain.groups[rod]
    node = first if end == TOP else last
    velocity = result.velocity_m_per_s[:, node]
    waves = result.waves
    if waves is not None and (rod, end) in waves.ports:
        return RodEnd(rod, end, body.area_m2, waves.compression_n[:, waves.port(rod, end)], velocity)
    return RodEnd(rod, end, body.area_m2, _attached_compression_n(result, node, end, range(first, last + 1)), velocity)


def _attached_compression_n(result: Any, node: int, end: str, own: range) -> np.ndarray:
    """The compression at a lumped rod's end: the connectors there (not the rod's own links between its
    segments ``own``), the pulse or contact at the top of the impact body, the rock at the bottom of the
    rock body."""
    chain, columns = result.chain, None
    total = np.zeros(len(result.time_s))
    for link in chain.links:
        if link.body_a in own and link.body_b in own:
            continue
        if (end == TOP and link.body_b == node) or (end == BOTTOM and link.body_a == node):
            columns = columns or _link_forces(result)
            total = total + columns[f"{link.name}_force_n"]
    if end == TOP and node == chain.impact_body and result.impact_force_n is not None:
        total = total + result.impact_force_n
    if end == BOTTOM and node == chain.bit_body and result.rock_force_n is not None:
        total = total + result.rock_force_n
    return total


def _link_forces(result: Any) -> dict[str, np.ndarray]:
    return link_series(result.chain, result.position_m, result.velocity_m_per_s,
                       None if result.waves is None else result.waves.joint_force_n)


def stress_columns(result: Any) -> dict[str, np.ndarray]:
    """``<rod>_top_stress_pa`` and ``<rod>_bottom_stress_pa`` of every rod (compression positive)."""
    out = {}
    for rod in rods(result.scene):
        for end in (TOP, BOTTOM):
            part = rod_end(result, rod, end)
            out[f"{rod}_{end}_stress_pa"] = part.compression_n / part.area_m2
    return out


@dataclass(frozen=True)
class BlowFigures:
    """Per blow (rows) of one rod end: the largest compression and tension (N, tension positive) and the
    energy through the section along +x (J)."""

    compression_n: np.ndarray
    tension_n: np.ndarray
    energy_j: np.ndarray


def blow_figures(result: Any, rod: str, end: str) -> BlowFigures:
    """The end's figures of every blow that started in the run (module doc)."""
    waves = result.waves
    if waves is not None and (rod, end) in waves.ports:
        port = waves.port(rod, end)
        return BlowFigures(waves.blow_compression_n[:, port], waves.blow_tension_n[:, port], waves.blow_energy_j[:, port])
    part = rod_end(result, rod, end)
    ends, starts = _blow_index(result), _blow_index(result, closing=False)
    count = int(max(ends.max(initial=0), starts.max(initial=0))) + 1
    compression, tension, energy = np.zeros(count), np.zeros(count), np.zeros(count)
    power = part.compression_n * part.velocity_m_per_s
    steps = np.diff(result.time_s) * 0.5 * (power[1:] + power[:-1])
    np.maximum.at(compression, starts, part.compression_n)
    np.maximum.at(tension, starts, -part.compression_n)
    np.add.at(energy, ends[1:], steps)
    return BlowFigures(compression, tension, energy)


def rock_energy_per_blow_j(result: Any) -> np.ndarray:
    """int F_r v_bit dt over every blow that started in the run: the formulation's (integrated over every
    step) with wave rods, else the trapezoidal rule on the samples."""
    if result.waves is not None and len(result.waves.blow_rock_work_j):
        return result.waves.blow_rock_work_j
    blows = _blow_index(result)
    power = result.rock_force_n * result.bit_velocity_m_per_s
    out = np.zeros(int(blows.max()) + 1 if len(blows) else 0)
    np.add.at(out, blows[1:], np.diff(result.time_s) * 0.5 * (power[1:] + power[:-1]))
    return out


def _blow_index(result: Any, closing: bool = True) -> np.ndarray:
    """The blow of every sample: a sample at a blow start closes the blow before (``closing``: the steps
    that end there), or opens its own (the values there, the strike's among them)."""
    period = result.scene.impact.period_s
    if closing:
        return np.maximum(np.ceil(result.time_s / period - 1e-9).astype(int) - 1, 0)
    return np.floor(result.time_s / period + 1e-9).astype(int)


# Stress waves in a segmented rod (a rod of length L split into N lumped segments, models.drill.chain, is a
# discrete wave-guide: its long waves travel at c = sqrt(E / rho), its cut-off is omega_max = 2 c N / L, so a
# pulse of duration tau is carried faithfully once N >> L / (c tau)): the travel time of a pulse from the struck
# end to the rock, between the instants the impact force and the rock force first reach half of their peaks.

def first_crossing_s(time_s: np.ndarray, values: np.ndarray, fraction: float = 0.5) -> float:
    """First time ``values`` reaches ``fraction`` of its peak, linearly interpolated between samples."""
    level = fraction * np.max(values)
    i = int(np.argmax(values >= level))
    if i == 0:
        return float(time_s[0])
    t0, t1, v0, v1 = time_s[i - 1], time_s[i], values[i - 1], values[i]
    return float(t0 + (level - v0) / (v1 - v0) * (t1 - t0))


def travel_time_s(result: Any) -> float:
    """Half-peak arrival of the rock force minus half-peak arrival of the impact force."""
    return first_crossing_s(result.time_s, result.rock_force_n) - first_crossing_s(result.time_s, result.impact_force_n)


def transmitted_pulse_n(result: Any, time_s: np.ndarray) -> np.ndarray:
    """The rock force interpolated onto ``time_s`` (to compare runs of different segmentations)."""
    return np.interp(time_s, result.time_s, result.rock_force_n)
