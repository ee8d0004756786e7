"""The waves leaving every port over one step of the characteristics, from the exact solution's pieces.

A step that the stepper (models.waves.stepping) splits, at a switch, a pulse phase change or a break of an
arriving wave, is a sequence of *segments* over which every port's node follows the exact solution. At a
port the outgoing wave is w_out = v - w_in (models.drill.wave_rod): its exact values at each segment's
ends are the node's velocity less the arriving wave there. Where it jumps between two segments (a contact
closing on a face, a front arriving at a massless joint, a pulse's end) or its slope does (a kink: a contact
opening on a massless face, a rock that starts unloading under one, a kink arriving there) the step keeps a *break*
(models.waves.history): the wave is stored as lines between its breaks, each with its exact end value and
the start value that keeps its mean, mean = (x(b) - x(a)) / (b - a) - mean of w_in over [a, b] (the node's
exact displacement): a peak at a front or a kink is read where it is, not between two grid times. Where the
wave and its slope are continuous (behind a body with mass) the step stays one line, as a step without
events. A jump below JUMP and a kink whose slope change over a step is below KINK of the run's wave scale (its
strike velocity, or its pulse over the smallest impedance) are no breaks: a kink left in a line moves its values
by at most an eighth of that (a front transmitted and reflected at every joint and bounced on for many blows
would otherwise make every step a break). A segment shorter than TINY of the
step (a switch located at its start, the round-off of a front's time) carries no values: at a front the
contact that opens on it does so at the front, not one round-off later with a pull in between.

The readings of a port over the step (its largest compression and tension, the energy through it) come
from the exact values at every segment's ends, not from the stored lines' start values.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .history import PIECE_END, PIECE_LEFT, PIECE_RIGHT, PIECE_START

TINY = 1e-9  # a segment shorter than this fraction of the step carries no values
SHORT = 1e-4  # a line shorter than this fraction goes through its exact end values (its mean is round-off)
JUMP = 1e-4  # a jump of the outgoing wave beyond this share of the wave scale is a break
KINK = 1e-3  # so is a change of its slope times the step beyond this share


@dataclass(frozen=True)
class Segment:
    """Where the nodes follow one exact solution within a step: from ``begin`` to ``end`` (fractions of the
    step), the ports' nodes' positions, velocities and arriving waves at both ends (arrays over ports)."""

    begin: float
    end: float
    x0: np.ndarray
    x1: np.ndarray
    v0: np.ndarray
    v1: np.ndarray
    a0: np.ndarray
    a1: np.ndarray
    d0: np.ndarray  # the outgoing wave's slope (1/s) at both ends (a kink between segments is a break too)
    d1: np.ndarray
    solved: bool = True  # False: a step of the compiled kernel, whose nodes' values are not kept (only its waves)
    samples: tuple[int, int] = (-1, -1)  # the samples recorded at its start and end (-1: none)


@dataclass
class StepWaves:
    """The outgoing waves of some ports over a step (arrays over those ports): a line (``left``, ``right``) with
    the exact ``start`` value, and for a port with breaks (``pieces``: its index among the ports -> rows (end
    fraction, left, right, exact start)) its first piece's left and start and its last piece's right."""

    left: np.ndarray
    right: np.ndarray
    start: np.ndarray
    pieces: dict[int, np.ndarray]

    def leaving_square(self) -> np.ndarray:
        """int over the step of each port's wave^2, / h."""
        out = (self.left**2 + self.left * self.right + self.right**2) / 3.0
        for j, rows in self.pieces.items():
            lengths = np.diff(np.concatenate([[0.0], rows[:, PIECE_END]]))
            left, right = rows[:, PIECE_LEFT], rows[:, PIECE_RIGHT]
            out[j] = float(np.sum(lengths * (left * left + left * right + right * right) / 3.0))
        return out


def outgoing(segments: list[Segment], step_s: float, ports: np.ndarray, scale_m_per_s: float) -> StepWaves:
    """The outgoing waves of ``ports`` over the step (module doc; ``scale_m_per_s`` the wave scale)."""
    kept = _kept(segments)
    starts = np.array([s.v0[ports] - s.a0[ports] for s in kept])
    ends = np.array([s.v1[ports] - s.a1[ports] for s in kept])
    # a line over the whole step: its mean from the nodes' displacement less the arriving waves' mean
    arriving = sum((s.end - s.begin) * 0.5 * (s.a0[ports] + s.a1[ports]) for s in segments)
    moved = segments[-1].x1[ports] - segments[0].x0[ports]
    right, start = ends[-1], starts[0]
    waves = StepWaves(2.0 * (moved / step_s - arriving) - right, right.copy(), start.copy(), {})
    if len(kept) == 1:
        return waves
    kinks = np.abs(np.array([s.d0[ports] for s in kept[1:]]) - np.array([s.d1[ports] for s in kept[:-1]]))
    jumps = (np.abs(starts[1:] - ends[:-1]) > JUMP * scale_m_per_s) | (kinks * step_s > KINK * scale_m_per_s)
    for j in np.flatnonzero(jumps.any(axis=0)):
        port = ports[j]
        cuts = [0.0] + [kept[i + 1].begin for i in range(len(kept) - 1) if jumps[i, j]] + [1.0]
        rows = []
        for begin, end in itertools.pairwise(cuts):
            inside = [i for i, s in enumerate(kept) if s.begin >= begin - TINY and s.end <= end + TINY]
            right, start = ends[inside[-1], j], starts[inside[0], j]
            if end - begin < SHORT:
                left = start
            else:
                moved = _position(segments, end, port) - _position(segments, begin, port)
                mean_in = sum((s.end - s.begin) * 0.5 * (s.a0[port] + s.a1[port]) for s in segments
                              if s.begin >= begin - TINY and s.end <= end + TINY)
                left = 2.0 * (moved / step_s - mean_in) / (end - begin) - right
            rows.append((end, left, right, start))
        waves.pieces[int(j)] = rows = np.array(rows)
        waves.left[j], waves.start[j], waves.right[j] = rows[0, PIECE_LEFT], rows[0, PIECE_START], rows[-1, PIECE_RIGHT]
    return waves


def _kept(segments: list[Segment]) -> list[Segment]:
    """The segments that carry values (longer than TINY; the longest when none is)."""
    return [s for s in segments if s.end - s.begin > TINY] or [max(segments, key=lambda s: s.end - s.begin)]


def _position(segments: list[Segment], fraction: float, port: int) -> float:
    """The port's node position at ``fraction`` of the step (segments cover the step in order)."""
    for s in segments:
        if fraction <= s.begin + TINY:
            return float(s.x0[port])
    return float(segments[-1].x1[port])


@dataclass
class PortReadings:
    """Per port over a step: the largest compression and tension (N, tension positive) at the exact values
    of every segment's ends, and the energy through the section along +x (J)."""

    compression_n: np.ndarray
    tension_n: np.ndarray
    energy_j: np.ndarray
    arriving_j: np.ndarray  # the energy the arriving wave brings, Z int w_in^2 dt
    kept: list[Segment]  # the segments whose ends the values are read at
    compression_index: np.ndarray  # per port, where its compression is: index into the kept segments' ends
    tension_index: np.ndarray  # (their starts, then their ends)

    def at(self, index: np.ndarray, port: int) -> tuple[Segment, int]:
        """The segment and its end (0 start, 1 end) of a port's value at ``index`` (compression or tension)."""
        return self.kept[index[port] % len(self.kept)], int(index[port] // len(self.kept))


def readings(segments: list[Segment], waves: StepWaves, step_s: float, ports: np.ndarray,
             signs: np.ndarray, impedances: np.ndarray, down: np.ndarray) -> PortReadings:
    """The readings of ``ports`` (``waves`` theirs) over the step (module doc); ``signs`` sigma Z, ``down`` +1 at
    a top port."""
    kept = _kept(segments)
    v = np.array([s.v0[ports] for s in kept] + [s.v1[ports] for s in kept])
    a = np.array([s.a0[ports] for s in kept] + [s.a1[ports] for s in kept])
    values = signs[ports] * (v - 2.0 * a)
    arriving = 0.0
    for s in segments:
        a0, a1 = s.a0[ports], s.a1[ports]
        arriving = arriving + (s.end - s.begin) * (a0**2 + a0 * a1 + a1**2) / 3.0
    energy = down[ports] * impedances[ports] * step_s * (waves.leaving_square() - arriving)
    return PortReadings(values.max(axis=0), np.maximum(-values.min(axis=0), 0.0), energy,
                        impedances[ports] * step_s * arriving, kept, values.argmax(axis=0), values.argmin(axis=0))


@dataclass(frozen=True)
class BodyMotion:
    """The ports' nodes moving as bodies with mass over a step (arrays over ports): a velocity quadratic in the
    fraction s of the step through v0 and v1 that moves them by x1 - x0,
    q(s) = v0 + beta s + gamma s^2, q(1) = v1, int_0^1 q ds = (x1 - x0) / h."""

    x0: np.ndarray
    x1: np.ndarray
    v0: np.ndarray
    v1: np.ndarray
    step_s: float

    @cached_property
    def gamma(self) -> np.ndarray:
        return 3.0 * (self.v1 - self.v0) - 6.0 * ((self.x1 - self.x0) / self.step_s - self.v0)

    @cached_property
    def beta(self) -> np.ndarray:
        return self.v1 - self.v0 - self.gamma

    def velocity(self, s: float) -> np.ndarray:
        return self.v0 + self.beta * s + self.gamma * s * s

    def acceleration(self, s: float) -> np.ndarray:
        return (self.beta + 2.0 * self.gamma * s) / self.step_s

    def position(self, s: float) -> np.ndarray:
        return self.x0 + self.step_s * (self.v0 * s + self.beta * s * s / 2.0 + self.gamma * s**3 / 3.0)


def body_segments(segments: list[Segment], motion: BodyMotion) -> list[Segment]:
    """The segments of a step (their times and arriving waves) with the ports' nodes moving as bodies whose
    states at the step's ends ``motion`` gives (Exudyn's): where the element solved the step itself
    (``solved``), its predicted motion (which has the bodies' response to a front within the step) corrected
    by the quadratic that meets Exudyn's end states; else ``motion``'s quadratic."""
    if not all(s.solved for s in segments):
        return [_moved(s, motion) for s in segments]
    first, last = segments[0], segments[-1]
    correction = BodyMotion(np.zeros_like(motion.x0), (motion.x1 - motion.x0) - (last.x1 - first.x0),
                            motion.v0 - first.v0, motion.v1 - last.v1, motion.step_s)
    return [Segment(s.begin, s.end, s.x0 + correction.position(s.begin), s.x1 + correction.position(s.end),
                    s.v0 + correction.velocity(s.begin), s.v1 + correction.velocity(s.end), s.a0, s.a1,
                    s.d0 + correction.acceleration(s.begin), s.d1 + correction.acceleration(s.end), True, s.samples)
            for s in segments]


def _moved(s: Segment, motion: BodyMotion) -> Segment:
    """``s`` with the ports' nodes moving as ``motion``'s quadratic (rows: its start and its end)."""
    arriving = (s.a1 - s.a0) / max(s.end - s.begin, TINY)
    ends = np.array([[s.begin], [s.end]])
    x, v, d = motion.position(ends), motion.velocity(ends), motion.acceleration(ends) - arriving
    return Segment(s.begin, s.end, x[0], x[1], v[0], v[1], s.a0, s.a1, d[0], d[1])


GAUSS_POINTS, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(3)
GAUSS_FRACTIONS = (0.5 * (1.0 + GAUSS_POINTS))[:, None]  # u of each point, a column
# the cubic through p0, p1 with slopes m0, m1 (per unit of u) at u = 0, 1, at each point u: the weights of p0, m0, p1, m1
_U = GAUSS_FRACTIONS
HERMITE = (2 * _U**3 - 3 * _U**2 + 1, _U**3 - 2 * _U**2 + _U, -2 * _U**3 + 3 * _U**2, _U**3 - _U**2)


def port_work_j(segments: list[Segment], moved: list[Segment], motion: BodyMotion, ports: np.ndarray,
                impedances: np.ndarray) -> float:
    """int Z (v - 2 w_in) v dt into the rods at ``ports`` over the step, v the bodies' motion (``moved``:
    :func:`body_segments` of ``segments`` and ``motion``) and w_in each segment's arriving line: Gauss-Legendre on
    3 points per segment (rows: the points)."""
    impedance = impedances[ports]
    total = 0.0
    for s, m in zip(segments, moved, strict=True):
        length = s.end - s.begin
        a0, a1 = s.a0[ports], s.a1[ports]
        if s.solved:  # between the segment's ends: its velocities (and slopes) as a cubic
            h = length * motion.step_s
            v = HERMITE[0] * m.v0[ports] + HERMITE[1] * (h * (m.d0[ports] + (a1 - a0) / h)) \
                + HERMITE[2] * m.v1[ports] + HERMITE[3] * (h * (m.d1[ports] + (a1 - a0) / h))
        else:
            v = motion.velocity(s.begin + GAUSS_FRACTIONS * length)[:, ports]
        arriving = a0 + GAUSS_FRACTIONS * (a1 - a0)
        for weight, power in zip(GAUSS_WEIGHTS, np.sum(impedance * (v - 2.0 * arriving) * v, axis=1), strict=True):
            total += 0.5 * weight * length * float(power)
    return total * motion.step_s


__all__ = ["BodyMotion", "Segment", "StepWaves", "body_segments", "outgoing", "port_work_j", "readings"]
