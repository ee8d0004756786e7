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

Crater memory: the law keeps x_n when contact is lost, and a contact regained reloads along k_n up
to F_th, so within a blow it remembers its crater.

Indexing (``indexed``; models.drill.indexing): a share eta (``fresh_fraction``) of the blow's footprint
lands on fresh rock, the rest on rock the last blow crushed (or on ridges it left). Only eta of the
bit's crushing stroke advances the hole; the rest compacts what is already crushed, so the crushing
force hardens: with the blow's threshold tau as a second state,

    crushing:  x_n' = eta v,   tau' = k_n (1 - eta) v   (F = tau: the spring k_n (x - x_n) keeps up)

and every blow starts at tau = F_th (:meth:`JenkinsRock.start_blow`; the force is kept if the bit
already presses harder). eta = 1 is Eq. 1, 2. The rows stay affine in the states; eta is a
parameter of the law, set per blow.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np

from .backends import NUMERIC, Backend
from .base import POSITION, VELOCITY, RockLaw, State, trapezoidal_plastic_work_j
from .modes import ONE, Mode, ModeTable, Switch

DampingMode = Literal["contact", "always"]
FREE, CONTACT, CLIPPED, CRUSHING = "free", "contact", "clipped", "crushing"
BOTTOM, THRESHOLD = "bottom_m", "threshold_n"


@dataclass(frozen=True)
class JenkinsRock(RockLaw):
    """The paper's visco-elastic-plastic rock (Eq. 1, 2): a spring k_n in series with a dry-friction slider.

    With penetration d = x_bit - x_n: no force off the bottom; F = k_n d (+ rock damping) in contact; F = F_th
    while crushing, the bottom x_n advancing with the bit (module doc). A :class:`RockLaw`.

    Parameters
    ----------
    stiffness_n_per_m : float
        k_n, positive.
    damping_n_s_per_m : float
        c_n, at least 0.
    threshold_n : float
        F_th, positive (inf: an elastic rock).
    damping_mode : {"contact", "always"}, default "contact"
        c_n only while the bit touches the rock, the total force clipped at zero; or Eq. 4 literally.
    indexed : bool, default False
        Under an indexing model: the blow's threshold a state (module doc).
    fresh_fraction : float, default 1.0
        eta in (0, 1], the share of the blow on fresh rock (below 1 only when ``indexed``).

    Raises
    ------
    ValueError
        For parameters out of their ranges.

    Examples
    --------
    >>> from rpdrill.rocklaw import JenkinsRock
    >>> law = JenkinsRock(stiffness_n_per_m=5.1e8, damping_n_s_per_m=4.9e3, threshold_n=210e3)
    >>> law.name, round(law.crushing_penetration_m * 1e3, 4)  # F_th / k_n in mm
    ('jenkins', 0.4118)
    """

    stiffness_n_per_m: float
    damping_n_s_per_m: float
    threshold_n: float
    damping_mode: DampingMode = "contact"
    indexed: bool = False  # under an indexing model: the blow's threshold a state (module doc)
    fresh_fraction: float = 1.0  # eta, the share of the blow on fresh rock (``indexed`` only)

    name = "jenkins"
    bottom_index = 0

    def __post_init__(self) -> None:
        if self.stiffness_n_per_m <= 0 or self.threshold_n <= 0 or self.damping_n_s_per_m < 0 \
                or not 0 < self.fresh_fraction <= 1 or (self.fresh_fraction < 1 and not self.indexed):
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

    @property
    def resets_at_blows(self) -> bool:
        """Only an indexed law starts each blow at F_th."""
        return self.indexed

    @property
    def modes_follow_fresh_fraction(self) -> bool:
        """The crushing rates carry eta: a law per blow when it changes from blow to blow."""
        return self.indexed

    @property
    def state_names(self) -> tuple[str, ...]:
        """x_n, and the threshold tau of the current blow when ``indexed``."""
        return (BOTTOM, THRESHOLD) if self.indexed else (BOTTOM,)

    def initial_state(self) -> State:
        return (0.0, self.threshold_n) if self.indexed else (0.0,)

    def _capped(self, elastic: Any, state: Sequence[Any], backend: Backend, fresh_fraction: Any) -> Any:
        """min(k_n d, F_th); indexed, min(k_n d, tau + (1 - eta) (k_n d - tau)): the force the return map
        gives at any bit position from the states (exact within an Exudyn step while crushing)."""
        if not self.crushes:
            return elastic
        if not self.indexed:
            return backend.minimum(elastic, self.threshold_n)
        eta = self.fresh_fraction if fresh_fraction is None else fresh_fraction
        return backend.minimum(elastic, state[1] + (1.0 - eta) * (elastic - state[1]))

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend = NUMERIC,
                     fresh_fraction: Any = None) -> Any:
        """Eq. 1: clip(k_n d, 0, F_th) with d = x_bit - x_n, the force of the spring-slider pair (indexed:
        :meth:`_capped`; ``fresh_fraction``: eta as a symbolic variable, default the law's)."""
        elastic = self.stiffness_n_per_m * (bit_position_m - state[0])
        return backend.where(elastic > 0, self._capped(elastic, state, backend, fresh_fraction), 0.0)

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any],
              backend: Backend = NUMERIC, fresh_fraction: Any = None) -> Any:
        """Eq. 1 plus rock damping (module docstring), F >= 0 in ``contact`` mode.

        Terms of zero parameters (no damping, no crushing) are left out of the expression.
        """
        if self.damping_n_s_per_m == 0.0:
            return self.spring_force(bit_position_m, state, backend, fresh_fraction)
        elastic = self.stiffness_n_per_m * (bit_position_m - state[0])
        spring = self._capped(elastic, state, backend, fresh_fraction)
        damping = self.damping_n_s_per_m * bit_velocity_m_per_s
        if self.damping_mode == "always":
            return backend.where(elastic > 0, spring, 0.0) + damping
        return backend.where(elastic > 0, backend.maximum(spring + damping, 0.0), 0.0)

    def return_map(self, bit_position_m: float, state: State) -> State:
        """Eq. 2 integrated over a step: x_n <- max(x_n, x_bit - F_th / k_n). Indexed: the excess
        delta = x - x_n - tau / k_n > 0 gives x_n += eta delta, tau += k_n (1 - eta) delta."""
        if not self.indexed:
            return (max(state[0], bit_position_m - self.crushing_penetration_m),)
        bottom, threshold = state
        excess = bit_position_m - bottom - threshold / self.stiffness_n_per_m
        if excess <= 0:
            return state
        eta = self.fresh_fraction
        return (bottom + eta * excess, threshold + self.stiffness_n_per_m * (1.0 - eta) * excess)

    def start_blow(self, bit_position_m: float, state: State) -> State:
        """The state the next blow meets: indexed, tau <- max(F_th, k_n (x - x_n)) (a fresh threshold,
        the force kept); else unchanged (Eq. 1, 2 have no blows)."""
        if not self.indexed:
            return state
        return (state[0], max(self.threshold_n, self.stiffness_n_per_m * (bit_position_m - state[0])))

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """W_p = F_th (x_n - x_n(0)): the bottom moves only while the spring carries F_th (trapezoidal
        int F d(x_n) with a threshold state, exact while it is constant)."""
        if self.indexed:
            return trapezoidal_plastic_work_j(spring_force_n, bottom_m)
        return (self.threshold_n if self.crushes else 0.0) * (bottom_m - bottom_m[0])

    def modes(self) -> ModeTable:
        """The mode table of the module docstring over position x, velocity v, bottom_m and one:
        F_r rows k_n (x - x_n) + c_n v (contact), F_th + c_n v with x_n' = v (crushing; entered at
        x_n = x - F_th / k_n, the return map on the switching surface), 0 (clipped; free unless the
        damping acts ``always``)."""
        k, c = self.stiffness_n_per_m, self.damping_n_s_per_m
        # the threshold: a constant, or the blow's tau (indexed: hardening while crushing)
        threshold = {THRESHOLD: 1.0} if self.indexed else {ONE: self.threshold_n}
        rates = {BOTTOM: {VELOCITY: self.fresh_fraction}}
        if self.fresh_fraction < 1:
            rates[THRESHOLD] = {VELOCITY: k * (1.0 - self.fresh_fraction)}
        penetration = {POSITION: 1.0, BOTTOM: -1.0}
        total = {POSITION: k, BOTTOM: -k, VELOCITY: c}
        contact_exits = [Switch(penetration, -1, FREE)]
        if self.crushes:
            contact_exits.append(Switch({POSITION: k, BOTTOM: -k, **{name: -value for name, value in threshold.items()}},
                                        1, CRUSHING))
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
            table[CRUSHING] = Mode({**threshold, VELOCITY: c}, (Switch({VELOCITY: 1.0}, -1, CONTACT),),
                                   rates=rates,
                                   entry={BOTTOM: {POSITION: 1.0, **{name: -value / k for name, value in threshold.items()}}})
        return table

    def initial_mode(self, values: Mapping[str, float]) -> str:
        d, v = values[POSITION] - values[BOTTOM], values[VELOCITY]
        if d <= 0:
            return FREE
        threshold = values[THRESHOLD] if self.indexed else self.threshold_n
        if self.crushes and self.stiffness_n_per_m * d >= threshold and v > 0:
            return CRUSHING
        return CLIPPED if self._clips and self.stiffness_n_per_m * d + self.damping_n_s_per_m * v <= 0 else CONTACT

    @property
    def _clips(self) -> bool:
        """Contact damping clips the total force at zero (only a damper can make it negative)."""
        return self.damping_mode == "contact" and self.damping_n_s_per_m > 0
