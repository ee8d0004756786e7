"""Bilinear loading/unloading rock law, the force-penetration law of percussive drilling studies
(Lundberg; Depouhon and Detournay).

The bit loads the rock along a penetration stiffness k_l and unloads along a steeper stiffness
k_u > k_l, keeping a permanent indentation. Two states: the bottom p (the plastic offset,
where the unloading line reaches zero force; the borehole bottom x_n, never decreasing) and the
surface s <= p (where the current loading line starts). With x the bit position:

    F = max(0, min(k_l (x - s), k_u (x - p)))

Loading (on the line k_l (x - s), x rising) pushes p along so that the unloading line passes
through the current point, p = x - k_l (x - s) / k_u, i.e. p' = (1 - k_l / k_u) x'. Unloading and
reloading below the previous maximum follow k_u (x - p) with p fixed. When the bit leaves the
rock (x <= p) the next blow loads afresh from the indentation: s <- p.

A loading from the surface to a penetration u_max and full unloading leave the permanent
indentation u_max (1 - k_l / k_u) and dissipate k_l u_max^2 (1 - k_l / k_u) / 2 = int F dp; the
rock stores F^2 / (2 k_u). k_u = k_l is an elastic rock (no indentation, ``crushes`` False).

This law has no rock damping: a viscous term would need its own rule for the contact and the
clipping at zero force on each branch, and the bilinear studies model the losses by k_u > k_l.

Modes (:meth:`BilinearRock.modes`):

=========  ===================================================  ==========
mode       leaves when                                           next mode
=========  ===================================================  ==========
free       x - p rises through 0 (contact; s <- p on entry)      loading
loading    v falls through 0 (the maximum)                       unloading
unloading  k_u (x - p) - k_l (x - s) rises through 0 (x back     loading
           at the previous maximum)
unloading  x - p falls through 0 (contact lost)                  free
=========  ===================================================  ==========

p' = (1 - k_l / k_u) v in ``loading``, 0 otherwise; s' = 0. An elastic rock (k_u = k_l) leaves
``loading`` only when contact is lost.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rpdrill.rocklaw.backends import NUMERIC, Backend
from rpdrill.rocklaw.base import POSITION, VELOCITY, State, trapezoidal_plastic_work_j
from rpdrill.rocklaw.modes import Mode, ModeTable, Switch

FREE, LOADING, UNLOADING = "free", "loading", "unloading"
SURFACE, BOTTOM = "surface_m", "bottom_m"


@dataclass(frozen=True)
class BilinearRock:
    """Loading stiffness k_l, unloading stiffness k_u >= k_l; a :class:`rocklaw.base.RockLaw`."""

    loading_stiffness_n_per_m: float
    unloading_stiffness_n_per_m: float

    name = "bilinear"
    state_names = (SURFACE, BOTTOM)
    bottom_index = 1
    threshold_n = math.inf
    damping_n_s_per_m = 0.0

    def __post_init__(self) -> None:
        if not 0 < self.loading_stiffness_n_per_m <= self.unloading_stiffness_n_per_m < math.inf:
            raise ValueError(f"invalid rock parameters {self}: need 0 < k_l <= k_u < inf")

    @property
    def crushes(self) -> bool:
        """False for k_u = k_l (elastic at k_l: nothing is kept, no per-step update)."""
        return self.unloading_stiffness_n_per_m > self.loading_stiffness_n_per_m

    @property
    def crushing_penetration_m(self) -> float:
        """0 (indents from the first contact), inf for an elastic rock."""
        return 0.0 if self.crushes else math.inf

    @property
    def indentation_ratio(self) -> float:
        """1 - k_l / k_u: permanent indentation per unit of loading penetration."""
        return 1.0 - self.loading_stiffness_n_per_m / self.unloading_stiffness_n_per_m

    def initial_state(self) -> State:
        return (0.0, 0.0)

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend = NUMERIC) -> Any:
        """F = max(0, min(k_l (x - s), k_u (x - p)))."""
        surface, bottom = state
        loading = self.loading_stiffness_n_per_m * (bit_position_m - surface)
        unloading = self.unloading_stiffness_n_per_m * (bit_position_m - bottom)
        return backend.maximum(backend.minimum(loading, unloading), 0.0)

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any],
              backend: Backend = NUMERIC) -> Any:
        """The spring force: no rock damping in this law."""
        return self.spring_force(bit_position_m, state, backend)

    def return_map(self, bit_position_m: float, state: State) -> State:
        """x <= p (fully unloaded): s <- p; else p <- max(p, x - k_l (x - s) / k_u), written as
        s + (1 - k_l / k_u) (x - s) (exactly s for an elastic rock)."""
        surface, bottom = state
        if bit_position_m <= bottom:
            return (bottom, bottom)
        return (surface, max(bottom, surface + self.indentation_ratio * (bit_position_m - surface)))

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """W_p = int F dp (trapezoidal; exact on the loading line, where F is linear in p)."""
        return trapezoidal_plastic_work_j(spring_force_n, bottom_m)

    def modes(self) -> ModeTable:
        """The mode table of the module docstring over position x, surface_m s, bottom_m p, velocity v
        and one: F = k_l (x - s) while loading (p' = (1 - k_l / k_u) v; entered at p = s + (1 - k_l / k_u)
        (x - s), the return map on the switching surface), k_u (x - p) while unloading, 0 free
        (entered with s = p: the next blow loads afresh from the indentation)."""
        k_l, k_u, ratio = self.loading_stiffness_n_per_m, self.unloading_stiffness_n_per_m, self.indentation_ratio
        gap = {POSITION: 1.0, BOTTOM: -1.0}
        loading_exit = Switch({VELOCITY: 1.0}, -1, UNLOADING) if self.crushes else Switch(gap, -1, FREE)
        table = {
            FREE: Mode({}, (Switch(gap, 1, LOADING),), entry={SURFACE: {BOTTOM: 1.0}}),
            LOADING: Mode({POSITION: k_l, SURFACE: -k_l}, (loading_exit,),
                          rates={BOTTOM: {VELOCITY: ratio}},
                          entry={BOTTOM: {SURFACE: 1.0 - ratio, POSITION: ratio}}),
        }
        if self.crushes:
            reload_margin = {POSITION: k_u - k_l, BOTTOM: -k_u, SURFACE: k_l}  # k_u (x - p) - k_l (x - s)
            table[UNLOADING] = Mode({POSITION: k_u, BOTTOM: -k_u},
                                    (Switch(reload_margin, 1, LOADING), Switch(gap, -1, FREE)))
        return table

    def initial_mode(self, values: Mapping[str, float]) -> str:
        """free off the rock; loading on the loading line (to round-off) unless moving out; else unloading."""
        x, surface, bottom = values[POSITION], values[SURFACE], values[BOTTOM]
        if x <= bottom:
            return FREE
        loading = self.loading_stiffness_n_per_m * (x - surface)
        unloading = self.unloading_stiffness_n_per_m * (x - bottom)
        on_loading_line = unloading >= loading * (1 - 1e-9)
        return LOADING if not self.crushes or (on_loading_line and values[VELOCITY] >= 0) else UNLOADING
