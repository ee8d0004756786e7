"""What a run on the grid of the characteristics records (the stepper's part that writes, models.waves.stepping):
its samples, each blow's peaks at the rods' ends, and once a blow is done the largest stresses along every rod
and the gauges' waves over it (models.evaluation.wave_readings reads them).

Samples are taken every sample interval on the grid, on both sides of every jump (a strike, a switch, a front
arriving, a pulse's phase change) and, once a blow is done, where each port's largest compression and tension of
the blow were (``kept``: the rows a time series keeps beside its uniform grid, so that its largest sample of a
rod end's stress is the blow's peak and a front shows both its sides: models.evaluation.results).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .kernels import envelope
from .system import Key

COMPRESSION, TENSION = 0, 1


@dataclass
class Samples:
    time_s: list[float] = field(default_factory=list)
    states: list[np.ndarray] = field(default_factory=list)
    velocity: list[np.ndarray] = field(default_factory=list)
    forces: list[np.ndarray] = field(default_factory=list)  # rock, impact, then each rigid joint's
    works: list[np.ndarray] = field(default_factory=list)  # cumulative impact, internal (string) work
    waves_j: list[float] = field(default_factory=list)  # energy of the string's rods' waves in flight
    piston_j: list[float] = field(default_factory=list)  # a wave piston's energy
    compression: list[np.ndarray] = field(default_factory=list)  # every port's compression
    after: list[bool] = field(default_factory=list)  # recorded after a jump at its own time (a catch)
    kept: list[bool] = field(default_factory=list)  # a front's side or a blow's peak (module doc)

    def order(self) -> np.ndarray:
        """The samples in time order (a peak is added once its blow is done), before a jump before after it."""
        return np.lexsort((np.array(self.after, dtype=int), np.array(self.time_s)))


@dataclass(frozen=True)
class Snapshot:
    """A state the run passed, kept in case it is a blow's peak: what a sample of it needs besides the state."""

    time_s: float
    state: np.ndarray
    key: object
    after: bool
    works: np.ndarray
    waves_j: float
    piston_j: float


@dataclass
class BlowPeaks:
    """Per (port, COMPRESSION or TENSION) where the blow's largest value is so far: a sample's index or a
    :class:`Snapshot`."""

    where: dict[tuple[int, int], int | Snapshot] = field(default_factory=dict)

    def offer(self, port: int, kind: int, where: int | Snapshot) -> None:
        self.where[(port, kind)] = where

    def taken(self) -> list[int | Snapshot]:
        """The blow's peaks (module doc), emptied for the next blow."""
        out, self.where = list(self.where.values()), {}
        return out


TINY_FRACTION = 1e-9
ENVELOPE_STATIONS = 32  # sections along a rod where its blow's largest stresses are read


class Recorder:
    """The recording methods of :class:`models.waves.stepping.Stepper` (its state: samples, lines, statistics,
    peaks, works)."""

    def _record(self, t: float, w: np.ndarray, key: Key, after: bool = False, kept: bool = True,
                snapshot: Snapshot | None = None) -> int:
        """A sample (its index): the state, every node's velocity, the forces (rock, impact, rigid joints), the
        works, the energy in the string's rods and in a wave piston, every port's compression; ``kept`` a
        front's side or a peak (models.waves.recording); ``snapshot`` one taken before, with its works."""
        samples, layout, n = self.samples, self.layout, self.layout.n
        if "record" not in key.cache:  # velocities, forces and compressions as one matrix over w
            ports = self.port_signs[:, None] * key.velocity[self.port_nodes]
            ports[np.arange(len(self.ports)), layout.inputs + 2 * np.arange(len(self.ports))] -= 2.0 * self.port_signs
            rows = [key.velocity, key.rock_force[None], self.impact_row(key)[None],
                    np.array([key.constraints[name] for name in self.rigid_names]).reshape(-1, layout.size), ports]
            key.cache["record"] = np.vstack(rows)
        values = key.cache["record"] @ w
        forces = 2 + len(self.rigid_names)
        samples.time_s.append(t)
        samples.after.append(after)
        samples.kept.append(kept)
        samples.states.append(w.copy())
        samples.velocity.append(values[:n])
        samples.forces.append(values[n:n + forces])
        samples.compression.append(values[n + forces:])
        if snapshot is None:
            snapshot = self._snapshot(t, w, key, after)
        samples.works.append(snapshot.works)
        samples.piston_j.append(snapshot.piston_j)
        samples.waves_j.append(snapshot.waves_j)
        return len(samples.time_s) - 1

    def _snapshot(self, t: float, w: np.ndarray, key: Key, after: bool) -> Snapshot:
        """The state now with the works and the waves' energy a sample of it has."""
        return self._snapshot_of(t, w.copy(), key, after, self.works + np.array([0.0, self._step_flux[2]]),
                                 self.lines.square_sum, self._step_flux)

    def snapshot_if_wanted(self, t: float, w: np.ndarray, key: Key, after: bool) -> Callable[[], Snapshot]:
        """:meth:`_snapshot` of now, made when called (a peak there is rare): what it reads is copied now."""
        state, works = w.copy(), self.works + np.array([0.0, self._step_flux[2]])
        square_sum, flux = self.lines.square_sum.copy(), self._step_flux.copy()
        return lambda: self._snapshot_of(t, state, key, after, works, square_sum, flux)

    def _snapshot_of(self, t: float, state: np.ndarray, key: Key, after: bool, works: np.ndarray,
                     square_sum: np.ndarray, flux: np.ndarray) -> Snapshot:
        energies = self.lines.energies_j(square_sum)
        piston = 0.0 if self.piston_rod is None else energies[self.piston_rod]
        return Snapshot(t, state, key, after, works, float(np.sum(energies)) - piston + flux[0], piston + flux[1])

    def record_peaks(self) -> None:
        """The samples of the blow's peaks (models.waves.recording): kept, or recorded from their snapshots."""
        for where in self.peaks.taken():
            if isinstance(where, Snapshot):
                self._record(where.time_s, where.state, where.key, where.after, True, where)
            else:
                self.samples.kept[where] = True

    def offer_peaks(self, read, raised: tuple[np.ndarray, np.ndarray], ports: np.ndarray,
                    ends: tuple[Snapshot | Callable[[], Snapshot] | None, ...]) -> None:
        """Where a port's blow peak was raised in a step (``raised``: compression, tension masks over ``ports``):
        the sample at that segment's end, or the step's start or end ``ends``."""
        for kind, places, mask in ((COMPRESSION, read.compression_index, raised[0]),
                                   (TENSION, read.tension_index, raised[1])):
            for j in np.flatnonzero(mask):
                segment, end = read.at(places, j)
                index = segment.samples[end]
                if index < 0:
                    index = ends[end] if (segment.begin <= TINY_FRACTION if end == 0 else segment.end >= 1 - TINY_FRACTION) \
                        else None
                if callable(index):  # a snapshot taken only now that it is wanted
                    index = index()
                if index is not None:
                    self.peaks.offer(int(ports[j]), kind, index)


    def read_envelopes(self, k: int) -> None:
        """The largest compression and tension along every rod of the string over the blow that ends at step k
        (models.waves.kernels.envelope; at most ENVELOPE_STATIONS + 1 sections a rod, its cells' ends)."""
        if not self.statistics.energy_j:
            return
        first = (len(self.statistics.energy_j) - 1) * self.period_steps  # the blow's first step
        blow = {}
        for r, rod in enumerate(self.chain.waves):
            if r == self.piston_rod:
                continue
            delay = int(self.lines.delays[r])
            stations = np.unique(np.round(np.linspace(0, delay, min(delay, ENVELOPE_STATIONS) + 1)).astype(np.int64))
            largest, at_largest, lowest, at_lowest = envelope(self.lines.start, self.lines.right, 2 * r, 2 * r + 1,
                                                              self.lines.ring, first, k, delay, stations,
                                                              rod.impedance_n_s_per_m)
            blow[rod.name] = (stations / delay * rod.length_m, largest, at_largest * self.step_s, lowest,
                              at_lowest * self.step_s)
        self.statistics.envelopes.append(blow)
        steps, ring, traces = np.arange(first, k), self.lines.ring, {}
        for name, gauge in self.simulation.outputs.gauges.items():
            r = next(i for i, rod in enumerate(self.chain.waves) if rod.name == gauge.rod)
            rod, delay = self.chain.waves[r], int(self.lines.delays[r])
            j = round(gauge.position_m / rod.length_m * delay)  # the cell's end nearest the gauge
            down, up = (steps - j) % ring, (steps - delay + j) % ring
            traces[name] = (steps * self.step_s, self.lines.start[2 * r, down], self.lines.right[2 * r, down],
                            self.lines.start[2 * r + 1, up], self.lines.right[2 * r + 1, up])
        self.statistics.gauges.append(traces)

