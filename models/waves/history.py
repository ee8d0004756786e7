"""The waves in flight: every rod end's outgoing wave, step by step, carried to the other end.

On the grid t_k = k h of the characteristics a rod of transit time T is N = round(T / h) steps long
(the transit times as run, N h, are stated: :func:`delays`). Over each step the outgoing wave at a port
is the straight line through its values at the step's ends, (left, right): ``right`` the wave at the
step's end, ``left`` chosen so that the line keeps the step's mean, which the exact integration of the
node gives (left = 2 mean - right; the node's displacement over the step less the arriving wave's);
``start`` is the wave's exact value at the step's start (what the readings take: a peak, a front).
A front that falls on a grid time is a jump between two steps and is carried exactly. A front within a
step (a contact that closes between grid times, a pulse that ends there, a front that arrived there) is
a *break*: the step's wave is stored as lines between its breaks, each keeping its own mean, and the
break arrives at the other end at the same time into its step, where the stepper resets the arriving
line (models.waves.stepping): a front is carried at its time, not smeared over a step. A wave arrives
N steps after it left:

    incoming(port, k) = outgoing(other end of the rod, k - N).

Before the start each rod carries the waves of its initial state: at rest under a compression P,
d = P / (2 Z), u = -P / (2 Z).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..drill.wave_rod import WaveRod


def delays(rods: Sequence[WaveRod], step_s: float) -> tuple[int, ...]:
    """N = round(T / h) steps per rod (at least one)."""
    return tuple(max(1, round(rod.transit_time_s / step_s)) for rod in rods)


def transit_errors(rods: Sequence[WaveRod], step_s: float) -> dict[str, float]:
    """(N h - T) / T of every rod: the transit time as run against the rod's own."""
    return {rod.name: (n * step_s - rod.transit_time_s) / rod.transit_time_s
            for rod, n in zip(rods, delays(rods, step_s), strict=True)}


MAX_TRIES = 4096  # candidate steps searched (a step far below the period has as good ones nearby)


def wave_step_s(durations_s: Sequence[float], target_s: float, period_s: float, tolerance: float = 1e-3,
                tries: int | None = None) -> float:
    """The step of the characteristics: h = period / M (blows start on the grid) for the smallest
    M >= period / target that makes every duration (the rods' transit times, a prescribed pulse's length)
    a whole number of steps within ``tolerance`` (relative), among M up to 1.5 times the first (``tries``
    candidates); the best of them when none is."""
    first = max(1, math.ceil(period_s / target_s - 1e-9))
    tries = min(tries or max(1, first // 2), MAX_TRIES)  # a huge count is refused by the run's budget
    if not durations_s:
        return period_s / first
    transit = np.array(durations_s, dtype=float)
    counts = np.arange(first, first + tries)
    steps = period_s / counts
    ratio = transit[None, :] / steps[:, None]
    error = np.max(np.abs(np.maximum(np.round(ratio), 1) - ratio) / ratio, axis=1)
    good = np.flatnonzero(error <= tolerance)
    return float(steps[good[0]] if len(good) else steps[np.argmin(error)])


EDGE = 1e-9  # a break within this fraction of a step's end is at its end
# a step's pieces: rows (end, as a fraction of the step in (0, 1]; left; right; exact start value)
PIECE_END, PIECE_LEFT, PIECE_RIGHT, PIECE_START = range(4)


class WaveLines:
    """The outgoing waves of every port (2 per rod: top, bottom) over the last steps (module doc), with the
    integrals over each step of the wave and of its square kept as running sums over the waves in flight
    (a rod's energy and momentum at any step without summing its window). A step with breaks has its
    pieces in ``pieces`` (port, slot) and ``broken`` set; ``left``, ``right`` and ``start`` then hold its
    first piece's left and start and its last piece's right."""

    def __init__(self, rods: Sequence[WaveRod], step_s: float, initial_outgoing: np.ndarray, kept_steps: int = 0) -> None:
        self.rods, self.step_s = tuple(rods), step_s
        self.delays = np.array(delays(rods, step_s), dtype=int)
        # the waves in flight, and ``kept_steps`` more (a blow's, for the readings along the rods)
        self.ring = int(self.delays.max(initial=1)) + 1 + kept_steps
        ports = len(initial_outgoing)
        self.left = np.zeros((ports, self.ring))
        self.right = np.zeros((ports, self.ring))
        self.start = np.zeros((ports, self.ring))  # the exact value at the step's start
        self.square = np.zeros((ports, self.ring))  # int over the step of the wave^2, / h
        self.mean = np.zeros((ports, self.ring))  # int over the step of the wave, / h
        self.broken = np.zeros((ports, self.ring), dtype=np.uint8)  # 1: the step has breaks (``pieces``)
        self.pieces: dict[tuple[int, int], np.ndarray] = {}
        self.square_sum = np.zeros(ports)  # over the N steps before the next one stored
        self.mean_sum = np.zeros(ports)
        self.port_delays = np.repeat(self.delays, 2)
        self.impedances = np.array([rod.impedance_n_s_per_m for rod in self.rods])
        self.sources = np.arange(ports) ^ 1  # the other end of the same rod
        for rod in range(len(self.rods)):
            for port in (2 * rod, 2 * rod + 1):
                self._fill_port(port, rod, 0, float(initial_outgoing[port]))

    def incoming(self, step: int) -> tuple[np.ndarray, np.ndarray]:
        """(left, right) of the waves arriving at every port over step ``step`` (a broken step: its first
        piece's left and its last piece's right)."""
        k = (step - self.port_delays) % self.ring
        return self.left[self.sources, k], self.right[self.sources, k]

    def arriving_pieces(self, step: int, port: int) -> np.ndarray | None:
        """The pieces of the wave arriving at ``port`` over ``step`` (rows as ``pieces``), None without breaks."""
        source, slot = port ^ 1, (step - self.port_delays[port]) % self.ring
        return self.pieces[(source, slot)] if self.broken[source, slot] else None

    def arriving_breaks(self, step: int) -> list[tuple[float, int, float, float]]:
        """(fraction of the step, port, the line's value there, its slope per fraction) where an arriving
        wave's next piece starts within ``step``, in time order."""
        k = (step - self.port_delays) % self.ring
        broken = np.flatnonzero(self.broken[self.sources, k])
        out = []
        for port in broken:
            rows = self.pieces[(int(self.sources[port]), int(k[port]))]
            for i in range(1, len(rows)):
                begin, end = rows[i - 1, PIECE_END], rows[i, PIECE_END]
                if begin >= 1.0 - EDGE:  # a break a round-off before the step's end is the next step's start
                    continue
                out.append((float(begin), int(port), float(rows[i, PIECE_LEFT]),
                            float((rows[i, PIECE_RIGHT] - rows[i, PIECE_LEFT]) / (end - begin))))
        return sorted(out)

    def first_pieces(self, step: int) -> tuple[np.ndarray, np.ndarray]:
        """(value at the step's start, slope per fraction of the step) of every port's arriving line over
        the first piece of ``step``."""
        left, right = self.incoming(step)
        slope = right - left
        k = (step - self.port_delays) % self.ring
        for port in np.flatnonzero(self.broken[self.sources, k]):
            rows = self.pieces[(int(self.sources[port]), int(k[port]))]
            slope[port] = (rows[0, PIECE_RIGHT] - rows[0, PIECE_LEFT]) / rows[0, PIECE_END]
        return left, slope

    def store(self, step: int, left: np.ndarray, right: np.ndarray, start: np.ndarray,
              ports: np.ndarray | None = None, again: bool = False) -> None:
        """The outgoing waves of ``ports`` (default: every port; arrays over every port) over ``step``, steps
        stored in order, each a line (left, right) with its exact ``start``; ``again``: a step stored before,
        its values replaced."""
        ports = np.arange(len(left)) if ports is None else ports
        k = step % self.ring
        left, right = left[ports], right[ports]
        square, mean = (left * left + left * right + right * right) / 3.0, 0.5 * (left + right)
        self._account(k, ports, square, mean, again, step)
        self.left[ports, k], self.right[ports, k], self.start[ports, k] = left, right, start[ports]
        self.broken[ports, k] = 0

    def store_pieces(self, step: int, port: int, rows: np.ndarray, again: bool = False) -> None:
        """One port's outgoing wave over ``step`` as pieces with breaks (rows as ``pieces``)."""
        k = step % self.ring
        lengths = np.diff(np.concatenate([[0.0], rows[:, PIECE_END]]))
        left, right = rows[:, PIECE_LEFT], rows[:, PIECE_RIGHT]
        square = float(np.sum(lengths * (left * left + left * right + right * right) / 3.0))
        mean = float(np.sum(lengths * 0.5 * (left + right)))
        ports = np.array([port])
        self._account(k, ports, np.array([square]), np.array([mean]), again, step)
        self.left[port, k], self.right[port, k], self.start[port, k] = left[0], right[-1], rows[0, PIECE_START]
        self.broken[port, k] = 1
        self.pieces[(port, k)] = rows

    def _account(self, k: int, ports: np.ndarray, square: np.ndarray, mean: np.ndarray, again: bool,
                 step: int) -> None:
        """The running sums with the step's integrals replacing those of the step leaving the window."""
        old = k if again else (step - self.port_delays[ports]) % self.ring
        self.square_sum[ports] += square - self.square[ports, old]
        self.mean_sum[ports] += mean - self.mean[ports, old]
        self.square[ports, k], self.mean[ports, k] = square, mean

    def _fill_port(self, port: int, rod: int, step: int, value: float) -> None:
        n = self.delays[rod]
        for k in range(step - n, step + 1):
            j = k % self.ring
            self.left[port, j] = self.right[port, j] = self.start[port, j] = self.mean[port, j] = value
            self.square[port, j] = value * value
            self.broken[port, j] = 0
        self.square_sum[port], self.mean_sum[port] = n * value * value, n * value

    def fill(self, rod: int, step: int, value: float) -> None:
        """Both ends of ``rod`` emitted ``value`` over the last N steps before ``step`` (a rod at a uniform
        velocity 2 value, unstressed: a piston at its strike, 0 when it is caught)."""
        for port in (2 * rod, 2 * rod + 1):
            self._fill_port(port, rod, step, value)

    def energy_j(self, rod: int) -> float:
        """Z int (d^2 + u^2) over the waves in flight: the rod's kinetic and strain energy."""
        return float(self.rods[rod].impedance_n_s_per_m * self.step_s * (self.square_sum[2 * rod]
                                                                         + self.square_sum[2 * rod + 1]))

    def energies_j(self, square_sum: np.ndarray | None = None) -> np.ndarray:
        """:meth:`energy_j` of every rod (from ``square_sum``, the running sums as they were, if given)."""
        square_sum = self.square_sum if square_sum is None else square_sum
        return self.impedances * self.step_s * (square_sum[::2] + square_sum[1::2])

    def momentum_n_s(self, rod: int) -> float:
        """Z int (d + u) over the waves in flight: the rod's momentum mu int v dx."""
        return float(self.rods[rod].impedance_n_s_per_m * self.step_s * (self.mean_sum[2 * rod]
                                                                         + self.mean_sum[2 * rod + 1]))
