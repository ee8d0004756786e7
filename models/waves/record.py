"""What a run with wave rods records of them, beside the usual histories (models.evaluation.results).

Every rod end is a *port* (``ports``: rod name and ``top`` or ``bottom``); at the result's samples its
compression (N, positive in compression) and, per blow, its largest compression and tension and the
energy through that section along +x, int P v dt (the formulations integrate these over every step of
the characteristics, so that no peak falls between two samples). The rigid joints' forces (a constraint
has no stretch to read a force from) come with the samples too.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..drill.wave_rod import WaveRod


@dataclass
class WaveRecord:
    """The rods of a run (module doc); arrays over samples x ports and blows x ports."""

    rods: tuple[WaveRod, ...]
    ports: tuple[tuple[str, str], ...]  # (rod, end) of every port, 2 per rod
    step_s: float  # the step of the characteristics
    transit_errors: dict[str, float]  # (N h - T) / T per rod
    compression_n: np.ndarray  # samples x ports
    blow_compression_n: np.ndarray  # blows x ports, the largest compression of each blow
    blow_tension_n: np.ndarray  # blows x ports, the largest tension (a positive number)
    blow_energy_j: np.ndarray  # blows x ports, int P v dt along +x
    blow_arriving_j: np.ndarray  # blows x ports, Z int w_in^2 dt: the energy the wave arriving there brings
    blow_rock_work_j: np.ndarray  # blows, int F_r v_bit dt
    energy_j: np.ndarray  # samples: the energy of the string's waves in flight
    joint_force_n: dict[str, np.ndarray] = field(default_factory=dict)  # rigid joint -> samples (F > 0 pulls)
    # the samples a time series keeps as rows beside its uniform grid: both sides of every front and every blow's
    # peaks at each rod end (models.waves.recording)
    kept: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    # per blow and string rod: (sections' positions from its top, largest compression there (N), its time, largest
    # tension, its time) (models.waves.stepping.Stepper.read_envelopes)
    envelopes: list[dict[str, tuple[np.ndarray, ...]]] = field(default_factory=list)
    # per blow and gauge: (each step's start time, the down-going wave at its start and end, the up-going's)
    gauges: list[dict[str, tuple[np.ndarray, ...]]] = field(default_factory=list)

    def port(self, rod: str, end: str) -> int:
        return self.ports.index((rod, end))

    def area_m2(self, rod: str) -> float:
        return next(r.area_m2 for r in self.rods if r.name == rod)
