"""What a run with wave rods reads along its string, beside the rods' ends (models.evaluation.rod_outputs): per
coupling (a connector joining two wave rods) and blow the energy the waves arriving from the upper rod bring
(``incident_j``), the net energy that crosses the upper rod's lower end (``energy_in_j``: incident less
reflected), the energy it passes into the lower rod, what it loses (its damper: in - out - the change of the
spring's energy over the blow) and its transmission, out / in; per rod and blow the largest compression and
tension at sections along it and when (its stress envelope: models.waves.stepping.Stepper.read_envelopes, from the
exact wave values at every step's ends), with their depth along the string.

The energies through the two sections are the formulation's per-blow figures (models.waves.record: integrated
over every step of the characteristics from the rods' stored waves); the coupling's energy at a blow's start is
F_spring^2 / (2 k) at the stretch there. Typed, so that an analysis over many runs (a hole, rod by rod) reads them
by name: ``result.wave_readings.couplings["coupling1"].transmission``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import rainflow

from ..drill.wave_rod import BOTTOM, TOP


@dataclass(frozen=True)
class CouplingBlows:
    """One coupling's figures, one value per blow that started in the run (module doc)."""

    name: str
    upper: str  # the rod above it (its lower end)
    lower: str  # the rod below it (its top end)
    incident_j: np.ndarray
    energy_in_j: np.ndarray
    energy_out_j: np.ndarray
    lost_j: np.ndarray

    @property
    def transmission(self) -> np.ndarray:
        """out / in per blow, the share of the net energy reaching it that it passes on (nan where none came): the
        energy delivered through couplings in a row is the product of theirs."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.energy_in_j > 0, self.energy_out_j / self.energy_in_j, np.nan)


@dataclass(frozen=True)
class RodEnvelope:
    """A rod's largest compression and tension (Pa, tension positive) at sections along it in every blow (blows x
    sections) and when, the sections' distance from its top and their depth along the string (from the top of its
    first rod, the rods end to end)."""

    rod: str
    position_m: np.ndarray
    depth_m: np.ndarray
    compression_pa: np.ndarray
    compression_time_s: np.ndarray
    tension_pa: np.ndarray
    tension_time_s: np.ndarray

    def largest(self, blows: slice = slice(None)) -> dict[str, float]:
        """Over ``blows``: the largest compression and tension anywhere in the rod and the depth where."""
        compression, tension = self.compression_pa[blows], self.tension_pa[blows]
        i = np.unravel_index(np.argmax(compression), compression.shape)
        j = np.unravel_index(np.argmax(tension), tension.shape)
        return {"compression_pa": float(compression[i]), "compression_depth_m": float(self.depth_m[i[1]]),
                "tension_pa": float(tension[j]), "tension_depth_m": float(self.depth_m[j[1]])}


@dataclass(frozen=True)
class GaugeRecord:
    """A gauge on a wave rod (scene ``outputs.gauges``), at the end of the cell nearest it: at every step's start and
    end (two rows at each grid time: a front's both sides) the force F = Z (d - u) (compression positive), the
    particle velocity v = d + u, Z v, the down-going wave (F + Z v) / 2 = Z d and the up-going (F - Z v) / 2 = -Z u;
    per blow the energy that passes it along +x, int F v dt (ENTHRU), and its incident and reflected parts
    Z int d^2 dt and Z int u^2 dt (integrated over each step's line between its exact ends); the stress cycles of
    each blow (rainflow, ASTM E1049-85: (range Pa, count) pairs) and, with the rod's S-N curve, Miner's damage per
    blow sum n / N(S_a)."""

    name: str
    rod: str
    position_m: float
    area_m2: float
    time_s: np.ndarray
    force_n: np.ndarray
    velocity_m_per_s: np.ndarray
    impedance_velocity_n: np.ndarray
    down_n: np.ndarray
    up_n: np.ndarray
    energy_j: np.ndarray
    incident_j: np.ndarray
    reflected_j: np.ndarray
    cycles: list[list[tuple[float, float]]]
    damage: np.ndarray | None

    @property
    def blows_to_failure(self) -> float | None:
        """1 / the mean damage per blow (None without an S-N curve; inf when no cycle does damage)."""
        if self.damage is None:
            return None
        mean = float(np.mean(self.damage)) if len(self.damage) else 0.0
        return math.inf if mean == 0 else 1.0 / mean


@dataclass(frozen=True)
class WaveReadings:
    """The readings along a wave string (module doc)."""

    couplings: dict[str, CouplingBlows] = field(default_factory=dict)
    envelopes: dict[str, RodEnvelope] = field(default_factory=dict)
    gauges: dict[str, GaugeRecord] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """Plain lists per blow (``wave_readings.json`` of ``rpdrill simulate``)."""
        return {"couplings": {name: {"upper": c.upper, "lower": c.lower, "incident_j": c.incident_j.tolist(),
                                     "energy_in_j": c.energy_in_j.tolist(), "energy_out_j": c.energy_out_j.tolist(),
                                     "lost_j": c.lost_j.tolist(), "transmission": c.transmission.tolist()}
                              for name, c in self.couplings.items()},
                "envelopes": {name: {"depth_m": e.depth_m.tolist(), "compression_pa": e.compression_pa.tolist(),
                                     "tension_pa": e.tension_pa.tolist(), "largest": e.largest()}
                              for name, e in self.envelopes.items()},
                "gauges": {name: {"rod": g.rod, "position_m": g.position_m, "energy_j": g.energy_j.tolist(),
                                  "incident_j": g.incident_j.tolist(), "reflected_j": g.reflected_j.tolist(),
                                  "cycles": g.cycles, "damage": None if g.damage is None else g.damage.tolist(),
                                  "blows_to_failure": g.blows_to_failure}
                           for name, g in self.gauges.items()}}


def wave_readings(result: Any) -> WaveReadings | None:
    """The readings of a run's result (None without wave rods)."""
    waves = result.waves
    if waves is None:
        return None
    scene, chain = result.scene, result.chain
    rods = {rod.name for rod in waves.rods}
    blows = len(waves.blow_energy_j)
    starts = np.arange(blows + 1) * scene.impact.period_s
    couplings = {}
    for link in chain.links:
        connector = scene.drill_string.connectors.get(link.name)
        if connector is None or connector.from_body not in rods or connector.to_body not in rods:
            continue
        energy_in = waves.blow_energy_j[:, waves.port(connector.from_body, BOTTOM)]
        energy_out = waves.blow_energy_j[:, waves.port(connector.to_body, TOP)]
        stored = np.zeros(blows + 1)
        if not link.rigid:
            ends = np.clip(starts, result.time_s[0], result.time_s[-1])
            stretch = np.interp(ends, result.time_s, result.position_m[:, link.body_b]) - \
                np.interp(ends, result.time_s, result.position_m[:, link.body_a])
            stored = link.spring_force_n(stretch) ** 2 / (2.0 * link.stiffness_n_per_m)
        incident = waves.blow_arriving_j[:, waves.port(connector.from_body, BOTTOM)]
        couplings[link.name] = CouplingBlows(link.name, connector.from_body, connector.to_body, incident, energy_in,
                                             energy_out, energy_in - energy_out - np.diff(stored))
    return WaveReadings(couplings, _envelopes(result), _gauges(result))


def _gauges(result: Any) -> dict[str, GaugeRecord]:
    """Every gauge's :class:`GaugeRecord` from the run's per-blow traces (models.waves.record)."""
    waves, out = result.waves, {}
    step = waves.step_s
    for name, gauge in result.simulation.outputs.gauges.items():
        rod = next(r for r in waves.rods if r.name == gauge.rod)
        body = result.scene.drill_string.bodies[gauge.rod]
        z, blows = rod.impedance_n_s_per_m, [blow[name] for blow in waves.gauges]
        times, down, up, energy, incident, reflected, cycles, damage = [], [], [], [], [], [], [], []
        for start_s, d0, d1, u0, u1 in blows:
            times.append(np.column_stack([start_s, start_s + step]).ravel())
            down.append(np.column_stack([d0, d1]).ravel())
            up.append(np.column_stack([u0, u1]).ravel())
            incident.append(z * step * float(np.sum(d0 * d0 + d0 * d1 + d1 * d1)) / 3.0)
            reflected.append(z * step * float(np.sum(u0 * u0 + u0 * u1 + u1 * u1)) / 3.0)
            energy.append(incident[-1] - reflected[-1])
            stress = z * (down[-1] - up[-1]) / body.area_m2
            counted = [(float(r), float(n)) for r, n in rainflow.count_cycles(stress)] if len(stress) > 2 else []
            cycles.append(counted)
            if body.sn_curve is not None:
                ranges = np.array([r for r, _ in counted])
                counts = np.array([n for _, n in counted])
                damage.append(float(np.sum(counts / body.sn_curve.cycles_to_failure(0.5 * ranges))) if len(counted)
                              else 0.0)
        d = np.concatenate(down) if down else np.zeros(0)
        u = np.concatenate(up) if up else np.zeros(0)
        out[name] = GaugeRecord(name, gauge.rod, gauge.position_m, body.area_m2,
                                np.concatenate(times) if times else np.zeros(0), z * (d - u), d + u, z * (d + u),
                                z * d, -z * u, np.array(energy), np.array(incident), np.array(reflected), cycles,
                                np.array(damage) if body.sn_curve is not None else None)
    return out


def _envelopes(result: Any) -> dict[str, RodEnvelope]:
    """Every string rod's :class:`RodEnvelope`, the rods in the scene's order end to end for the depth."""
    waves = result.waves
    if not waves.envelopes:
        return {}
    out, depth = {}, 0.0
    for name, body in result.scene.drill_string.bodies.items():
        if name not in waves.envelopes[0]:
            continue
        position = waves.envelopes[0][name][0]
        area = body.area_m2
        parts = [np.array([blow[name][i] for blow in waves.envelopes]) for i in range(1, 5)]
        out[name] = RodEnvelope(name, position, depth + position, parts[0] / area, parts[1], parts[2] / area, parts[3])
        depth += body.length_m
    return out
