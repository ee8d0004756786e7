"""The runs of a hole: one steady run per distinct (rod count, layer, operating point), what each gives as a typed
record, and the record as the JSON file a resumed hole reads back.

A run is the scene of studies.hole.hole_scenes run as it asks (``steady_state: periodic``: for wave rods blows
until the per-blow figures settle, models.steady.wave_settling). Its record reads the settled blows (the
metrics' window): the rate, the advance and the energy reaching the rock per blow, the hammer's energy per
blow, the efficiencies, per coupling the energy it loses and its transmission per blow
(models.evaluation.wave_readings), the largest compression and tension along the rods (their stress envelopes)
with the rod and the section where, the regime, the blows run and the last change.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from ...models.definition.scene import Scene
from ...models.definition.validation import parse
from ...models.runs.scene_run import run
from ..inputs.reading import prepare_scene
from .hole_advice import advised_changes
from .hole_scenes import apply_changes


@dataclass(frozen=True)
class SegmentRun:
    """What one run of a hole's scene gives (module doc); stresses in Pa, energies per blow in J."""

    key: str
    rods: int
    layer: int
    scene_hash: str
    rate_m_per_s: float
    advance_per_blow_m: float
    rock_energy_per_blow_j: float
    hammer_energy_per_blow_j: float
    rock_transfer_efficiency: float
    energy_transfer_efficiency: float
    regime: str
    blows: int
    last_change: float
    compression_pa: float
    compression_rod: str
    compression_position_m: float
    tension_pa: float
    tension_rod: str
    tension_position_m: float
    coupling_lost_j: dict[str, float] = field(default_factory=dict)
    coupling_transmission: dict[str, float] = field(default_factory=dict)
    coupling_in_j: dict[str, float] = field(default_factory=dict)  # the net energy reaching it per blow
    coupling_out_j: dict[str, float] = field(default_factory=dict)  # the energy it passes into the rod below
    cpu_time_s: float = 0.0
    operating: dict[str, float | None] = field(default_factory=dict)  # the advised point's changes (advise)
    fixed_rate_m_per_s: float = math.nan  # the rate at the rig's own operating point (advise)

    def as_json(self) -> str:
        return json.dumps(asdict(self), indent=1, allow_nan=True)

    @classmethod
    def from_json(cls, text: str) -> SegmentRun:
        return cls(**json.loads(text))


def scene_hash(data: dict[str, Any], advise: dict[str, Any] | None = None) -> str:
    """A digest of a scene's data and the advisor's options (a resumed hole reruns a segment whose scene changed)."""
    payload = data if advise is None else [data, advise]
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]


def run_segment(task: tuple[str, int, int, dict[str, Any], str, dict[str, Any] | None]) -> SegmentRun:
    """Run one segment's scene (``(key, rods, layer, scene data, source, advise options or None)``, what a worker
    receives) into its record; with the advisor's options, the steady run at the point it finds (its rate at the
    rig's own point kept beside it)."""
    key, rods, layer, data, source, advise = task
    start = time.process_time()
    fixed = settled_record(key, rods, layer, data, source)
    if advise is None:
        return replace(fixed, scene_hash=scene_hash(data))
    changes = advised_changes(data, source, advise)
    advised = settled_record(key, rods, layer, apply_changes(data, changes), source)
    return replace(advised, scene_hash=scene_hash(data, advise), operating=changes,
                   fixed_rate_m_per_s=fixed.rate_m_per_s, cpu_time_s=time.process_time() - start)


def settled_record(key: str, rods: int, layer: int, data: dict[str, Any], source: str) -> SegmentRun:
    """The record of the steady run of the scene ``data`` (module doc)."""
    start = time.process_time()
    scene = parse(Scene, data, source)
    result = run(prepare_scene(scene, source), source=source)
    metrics, steady = result.metrics, result.steady_state
    period = scene.impact.period_s
    first = round(metrics["window_start_s"] / period)
    window = slice(first, first + int(metrics["window_blows"]))
    readings = result.raw.wave_readings
    lost, transmission, energy_in, energy_out = {}, {}, {}, {}
    largest = {"compression_pa": (0.0, "", math.nan), "tension_pa": (0.0, "", math.nan)}
    if readings is not None:
        for name, coupling in readings.couplings.items():
            lost[name] = float(np.mean(coupling.lost_j[window]))
            transmission[name] = float(np.nanmean(coupling.transmission[window]))
            energy_in[name] = float(np.mean(coupling.energy_in_j[window]))
            energy_out[name] = float(np.mean(coupling.energy_out_j[window]))
        for rod, envelope in readings.envelopes.items():
            found = envelope.largest(window)
            for kind in largest:
                if found[kind] > largest[kind][0]:
                    depth = found[kind.replace("_pa", "_depth_m")]
                    largest[kind] = (found[kind], rod, depth - float(envelope.depth_m[0] - envelope.position_m[0]))
    blows = int(metrics["window_blows"])
    return SegmentRun(
        key, rods, layer, scene_hash(data), metrics["penetration_rate_m_per_s"], metrics["advance_per_blow_m"],
        metrics["rock_energy_per_blow_j"], _hammer_energy(result, blows), metrics["rock_transfer_efficiency"],
        metrics["energy_transfer_efficiency"], steady.regime_name, steady.blows, steady.last_change,
        largest["compression_pa"][0], largest["compression_pa"][1], largest["compression_pa"][2],
        largest["tension_pa"][0], largest["tension_pa"][1], largest["tension_pa"][2], lost, transmission,
        energy_in, energy_out, time.process_time() - start)


def _hammer_energy(result: Any, blows: int) -> float:
    """The energy the hammer puts in per blow: the piston's blow energy, or the pulse's impact work per blow."""
    piston = result.raw.simulation.piston
    if piston is not None:
        return float(piston.blow_energy_j)
    metrics = result.metrics
    return float(metrics.get("impact_energy_j", math.nan)) / blows if blows else math.nan
