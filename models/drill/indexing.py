"""Bit indexing between blows: the angle the bit turned since the last blow sets how the next blow
meets the rock (the ``indexing`` effect).

What the literature gives. Percussive drilling models since Hustrulid and Fairhurst (1971) and
Lundberg (1973) assume ideal indexing: every blow strikes fresh rock, and the rock's
force-penetration law starts afresh at each blow. Hartman (1959, 1966) measured the volume a blow
removes against the index (the distance between successive blows): it is small when the blow
lands in the previous crater, largest at an intermediate index where the craters just meet, and
smaller again when the craters stand apart and leave ridges between them. Practice sets the rotation
speed so that the gauge buttons move a fixed fraction of their diameter per blow (Epiroc COP M
manual: 0.74 d, rpm = 1600 d / (pi D) at 2160 blows per minute).

The model (its assumptions, in one track: the gauge circle, whose buttons move furthest per blow).
A bit turned by theta since the last blow start moves its gauge buttons by the arc s = theta D / 2.
N gauge buttons stand at the pitch P = pi D / N, so the nearest crater of the last blow lies
e = |s - P round(s / P)| from a button's new position. A crater is w wide (``bit.crater_width_m``,
default the button diameter d). The share of the blow that advances the hole is

    eta = e / w    (e < w: the footprint overlaps the last crater by 1 - e / w: re-crushed rock)
    eta = w / e    (e > w: craters w wide every e leave a ridge e - w between them, which the blow
                    does not remove: the hole advances over w of every e of the track)

so eta = 1 (a fresh surface, craters just touching) at e = w, and eta >= ``MIN_FRESH_FRACTION``
(a blow in its own crater still deepens it). The rock law runs each blow with its eta
(``fresh_fraction``; rocklaw): Jenkins, only eta of the bit's crushing stroke advances the hole and
the crushing force hardens along k_n (1 - eta) (the rest compacts crushed rock), from F_th at every
blow start; bilinear, the loading surface a share eta of the way to fresh rock at the blow start
(1 - eta of the old crater's stiff reload kept). At a constant rotation speed the index per blow is
constant, so the best rotation speed is proportional to the blow frequency:

    n_best = 60 f w / (pi D)  [rpm]   (e = w, below the pitch aliasing at s = P / 2).

The angle comes from a prescribed ``rotation.speed_rpm`` (theta = 2 pi n / (60 f)) or from the
torsion line (the change of phi between blow starts; phi does not change before the first blow).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ...rocklaw import RockLaw, State
from ..definition.scene import Bit

MIN_FRESH_FRACTION = 0.01  # a blow into its own crater still deepens it (the threshold stays finite)
FRESH, CRATER, RIDGES = "fresh surface", "partly crushed crater", "ridges"


@dataclass(frozen=True)
class Indexing:
    """The indexing model of one scene (module doc); ``speed_rpm`` None: the angle from the torsion line."""

    bit: Bit
    speed_rpm: float | None
    frequency_hz: float

    @property
    def prescribed_angle_rad(self) -> float:
        """theta = 2 pi n / (60 f), the angle turned between two blow starts at the prescribed speed."""
        return 2.0 * math.pi * self.speed_rpm / 60.0 / self.frequency_hz

    def crater_distance_m(self, angle_rad: float) -> float:
        """e = |s - P round(s / P)|: from a gauge button's new position to the nearest crater of the last blow."""
        arc, pitch = abs(angle_rad) * self.bit.diameter_m / 2.0, math.pi * self.bit.diameter_m / self.bit.gauge_buttons
        return abs(arc - pitch * round(arc / pitch))

    def fresh_fraction(self, angle_rad: float) -> float:
        """eta = min(e / w, w / e), at least MIN_FRESH_FRACTION."""
        distance, width = self.crater_distance_m(angle_rad), self.bit.crater_m
        if distance == 0.0:
            return MIN_FRESH_FRACTION
        return max(MIN_FRESH_FRACTION, min(distance / width, width / distance))

    def regime(self, angle_rad: float) -> str:
        """What the next blow meets: a partly crushed crater (e < w), a fresh surface (e = w), ridges (e > w)."""
        distance, width = self.crater_distance_m(angle_rad), self.bit.crater_m
        if math.isclose(distance, width, rel_tol=1e-9):
            return FRESH
        return CRATER if distance < width else RIDGES

    def best_speed_rpm(self) -> float:
        """n = 60 f w / (pi D): the speed at which e = w (a constant index per blow)."""
        return 60.0 * self.frequency_hz * self.bit.crater_m / (math.pi * self.bit.diameter_m)


@dataclass
class BlowStarts:
    """The rock law and state of each blow of one run: the share eta of the angle turned since the
    last blow start (1 without indexing), the law with that eta, and its ``start_blow``. Call it at
    every blow start in order; ``fresh_fractions`` records eta of each blow."""

    rock: RockLaw
    indexing: Indexing | None
    initial_angle_rad: float
    fresh_fractions: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._last_angle_rad = self.initial_angle_rad

    def __call__(self, bit_position_m: float, state: State, angle_rad: float = 0.0) -> tuple[RockLaw, State]:
        """(the law of the blow starting now, the state it meets); ``angle_rad``: the torsion angle now
        (read without a prescribed speed)."""
        law = self.rock
        if self.indexing is not None:
            turned = self.indexing.prescribed_angle_rad if self.indexing.speed_rpm is not None \
                else angle_rad - self._last_angle_rad
            self._last_angle_rad = angle_rad
            law = replace(law, fresh_fraction=self.indexing.fresh_fraction(turned))
        self.fresh_fractions.append(law.fresh_fraction)
        return law, tuple(law.start_blow(bit_position_m, state))
