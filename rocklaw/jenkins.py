"""The paper's rock law (Eq. 1 and 2): a spring k_n in series with a dry-friction slider.

One state, the borehole bottom x_n (the slider position). With penetration d = x_bit - x_n:

* d <= 0: the bit is off the bottom, no force (the rock never pulls);
* 0 < k_n d < F_th: elastic contact, F = k_n d (+ rock damping, see below);
* k_n d >= F_th: crushing, F = F_th and the bottom advances with the bit (x_n' = x_bit').

Rock damping c_n (the paper's Eq. 4 writes c_n x_bit' in the bit equation) is offered two ways:

* ``contact`` (default): c_n acts only while the bit touches the rock and the total force is
  clipped at zero, F = max(F_spring + c_n v, 0). A rock that is not touched cannot damp the bit,
  and a damper cannot pull the bit into the rock; this is the physically consistent reading.
* ``always``: Eq. 4 taken literally, F = F_spring + c_n v at all times, also off the bottom
  and also pulling (for the cross-check against the paper's equations as printed).

Modes (:meth:`JenkinsRock.modes`; x_n' = x_bit' in ``crushing``, 0 otherwise):

=========  ==============================================  ==========
mode       leaves when                                      next mode
=========  ==============================================  ==========
free       d rises through 0 (contact made)                 contact
contact    d falls through 0 (contact lost)                 free
contact    k_n d rises through F_th (crushing starts)       crushing
contact    k_n d + c_n v falls through 0 (``contact``       clipped
           damping only: the total force is clipped at 0)
clipped    k_n d + c_n v rises through 0                    contact
clipped    d falls through 0                                free
crushing   v falls through 0 (crushing ends)                contact
=========  ==============================================  ==========

With damping_mode ``always``, or without rock damping, there is no ``clipped`` mode (k_n d + c_n v
= 0 is then d = 0); an elastic rock (F_th infinite) has no ``crushing`` mode.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np

from rpdrill.rocklaw.backends import NUMERIC, Backend
from rpdrill.rocklaw.base import POSITION, VELOCITY, State
from rpdrill.rocklaw.modes import ONE, Mode, ModeTable, Switch

DampingMode = Literal["contact", "always"]
FREE, CONTACT, CLIPPED, CRUSHING = "free", "contact", "clipped", "crushing"
BOTTOM = "bottom_m"


@dataclass(frozen=True)
class JenkinsRock:
    """Parameters of the paper's visco-elastic-plastic rock (Eq. 1, 2); a :class:`rocklaw.base.RockLaw`."""

    stiffness_n_per_m: float
    damping_n_s_per_m: float
    threshold_n: float
    damping_mode: DampingMode = "contact"

    name = "jenkins"
    state_names = (BOTTOM,)
    bottom_index = 0

    def __post_init__(self) -> None:
        if self.stiffness_n_per_m <= 0 or self.threshold_n <= 0 or self.damping_n_s_per_m < 0:
            raise ValueError(f"invalid rock parameters {self}")

    @property
    def loading_stiffness_n_per_m(self) -> float:
        return self.stiffness_n_per_m

    @property
    def unloading_stiffness_n_per_m(self) -> float:
        return self.stiffness_n_per_m

    @cached_property
    def crushing_penetration_m(self) -> float:
        """Penetration F_th / k_n at which the rock starts to crush (cached: the Exudyn element's return
        map reads it at every step)."""
        return self.threshold_n / self.stiffness_n_per_m

    @property
    def crushes(self) -> bool:
        """False for an elastic rock (F_th infinite): no slider, no return mapping."""
        return math.isfinite(self.threshold_n)

    def initial_state(self) -> State:
        return (0.0,)

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend = NUMERIC) -> Any:
        """Eq. 1: clip(k_n d, 0, F_th) with d = x_bit - x_n, the force of the spring-slider pair."""
        elastic = self.stiffness_n_per_m * (bit_position_m - state[0])
        capped = backend.minimum(elastic, self.threshold_n) if self.crushes else elastic
        return backend.where(elastic > 0, capped, 0.0)

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any],
              backend: Backend = NUMERIC) -> Any:
        """Eq. 1 plus rock damping (module docstring), F >= 0 in ``contact`` mode.

        Terms of zero parameters (no damping, no crushing) are left out of the expression.
        """
        if self.damping_n_s_per_m == 0.0:
            return self.spring_force(bit_position_m, state, backend)
        elastic = self.stiffness_n_per_m * (bit_position_m - state[0])
        spring = backend.minimum(elastic, self.threshold_n) if self.crushes else elastic
        damping = self.damping_n_s_per_m * bit_velocity_m_per_s
        if self.damping_mode == "always":
            return backend.where(elastic > 0, spring, 0.0) + damping
        return backend.where(elastic > 0, backend.maximum(spring + damping, 0.0), 0.0)

    def return_map(self, bit_position_m: float, state: State) -> State:
        """Eq. 2 integrated over a step: x_n <- max(x_n, x_bit - F_th / k_n), state = (x_n,)."""
        return (max(state[0], bit_position_m - self.crushing_penetration_m),)

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """W_p = F_th (x_n - x_n(0)): the bottom moves only while the spring carries F_th."""
        return (self.threshold_n if self.crushes else 0.0) * (bottom_m - bottom_m[0])

    def modes(self) -> ModeTable:
        """The mode table of the module docstring over position x, velocity v, bottom_m and one:
        F_r rows k_n (x - x_n) + c_n v (contact), F_th + c_n v with x_n' = v (crushing; entered at
        x_n = x - F_th / k_n, the return map on the switching surface), 0 (clipped; free unless the
        damping acts ``always``)."""
        k, c, threshold = self.stiffness_n_per_m, self.damping_n_s_per_m, self.threshold_n
        penetration = {POSITION: 1.0, BOTTOM: -1.0}
        total = {POSITION: k, BOTTOM: -k, VELOCITY: c}
        contact_exits = [Switch(penetration, -1, FREE)]
        if self.crushes:
            contact_exits.append(Switch({POSITION: k, BOTTOM: -k, ONE: -threshold}, 1, CRUSHING))
        if self._clips:
            contact_exits.append(Switch(total, -1, CLIPPED))
        table = {
            FREE: Mode({VELOCITY: c} if self.damping_mode == "always" and c > 0 else {},
                       (Switch(penetration, 1, CONTACT),)),
            CONTACT: Mode(total, tuple(contact_exits)),
        }
        if self._clips:
            table[CLIPPED] = Mode({}, (Switch(total, 1, CONTACT), Switch(penetration, -1, FREE)))
        if self.crushes:
            table[CRUSHING] = Mode({ONE: threshold, VELOCITY: c}, (Switch({VELOCITY: 1.0}, -1, CONTACT),),
                                   rates={BOTTOM: {VELOCITY: 1.0}},
                                   entry={BOTTOM: {POSITION: 1.0, ONE: -self.crushing_penetration_m}})
        return table

    def initial_mode(self, values: Mapping[str, float]) -> str:
        d, v = values[POSITION] - values[BOTTOM], values[VELOCITY]
        if d <= 0:
            return FREE
        if self.crushes and self.stiffness_n_per_m * d >= self.threshold_n and v > 0:
            return CRUSHING
        return CLIPPED if self._clips and self.stiffness_n_per_m * d + self.damping_n_s_per_m * v <= 0 else CONTACT

    @property
    def _clips(self) -> bool:
        """Contact damping clips the total force at zero (only a damper can make it negative)."""
        return self.damping_mode == "contact" and self.damping_n_s_per_m > 0
