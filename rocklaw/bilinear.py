"""Bilinear loading/unloading rock law, the force-penetration law of percussive drilling studies
(Lundberg; Depouhon and Detournay).

The bit loads the rock along a penetration stiffness k_l and unloads along a steeper stiffness
k_u > k_l, keeping a permanent indentation. Two states: the bottom p (the plastic offset,
where the unloading line reaches zero force; the borehole bottom x_n, never decreasing) and the
surface s <= p (where the current loading line starts). With x the bit position:

    F = max(0, min(k_l (x - s), k_u (x - p)))

Loading (on the line k_l (x - s), x rising) pushes p along so that the unloading line passes
through the current point, p = x - k_l (x - s) / k_u, i.e. p' = (1 - k_l / k_u) x'. Unloading and
reloading below the previous maximum follow k_u (x - p) with p fixed.

Crater memory: within a blow the law keeps its crater. A bit that leaves the rock (x <= p) and
comes back reloads along k_u up to the previous maximum, then loads on along k_l; losing contact
changes no state. How the *next blow* meets the rock is set at the blow's start
(:meth:`BilinearRock.start_blow`): a share eta (``fresh_fraction``) of the footprint on fresh rock
moves the surface
s <- s + eta (s_fresh - s), with s_fresh = min(p, x - F / k_l) the loading line through the current
point (p off the rock; the force is kept when the bit rests on the rock). eta = 1 (ideal
indexing, every blow on fresh rock, the default without an indexing model) starts each blow
afresh; eta = 0 re-crushes the same crater.

A loading from the surface to a penetration u_max and full unloading leave the permanent
indentation u_max (1 - k_l / k_u) and dissipate k_l u_max^2 (1 - k_l / k_u) / 2 = int F dp; the
rock stores F^2 / (2 k_u). k_u = k_l is an elastic rock (no indentation, ``crushes`` False).

This law has no rock damping: a viscous term would need its own rule for the contact and the
clipping at zero force on each branch, and the bilinear studies model the losses by k_u > k_l.

Modes (:meth:`BilinearRock.modes`):

=========  ===================================================  ==========
mode       leaves when                                           next mode
=========  ===================================================  ==========
free       x - p rises through 0 (contact on a fresh surface,    loading
           s = p)
lifted     x - p rises through 0 (contact regained, s < p: the   unloading
           crater is remembered)
loading    v falls through 0 (the maximum)                       unloading
unloading  k_u (x - p) - k_l (x - s) rises through 0 (x back     loading
           at the previous maximum)
unloading  x - p falls through 0 (contact lost)                  lifted
=========  ===================================================  ==========

p' = (1 - k_l / k_u) v in ``loading``, 0 otherwise; s' = 0. An elastic rock (k_u = k_l) has only
``free`` and ``loading`` and leaves ``loading`` only when contact is lost.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .backends import NUMERIC, Backend
from .base import POSITION, VELOCITY, RockLaw, State, trapezoidal_plastic_work_j
from .modes import Mode, ModeTable, Switch

FREE, LIFTED, LOADING, UNLOADING = "free", "lifted", "loading", "unloading"
SURFACE, BOTTOM = "surface_m", "bottom_m"


@dataclass(frozen=True)
class BilinearRock(RockLaw):
    """The bilinear loading/unloading rock: F = max(0, min(k_l (x - s), k_u (x - p))) (module doc).

    Loading along k_l pushes the bottom p so that the unloading line k_u passes through the current point;
    a load to u_max and full unloading leave the indentation u_max (1 - k_l / k_u). A :class:`RockLaw`.

    Parameters
    ----------
    loading_stiffness_n_per_m : float
        k_l, positive.
    unloading_stiffness_n_per_m : float
        k_u >= k_l (equal: an elastic rock).
    fresh_fraction : float, default 1.0
        eta in (0, 1], the share of the next blow on fresh rock (models.drill.indexing).

    Raises
    ------
    ValueError
        Unless 0 < k_l <= k_u < inf and 0 < eta <= 1.

    Examples
    --------
    >>> from rpdrill.rocklaw import BilinearRock, force_and_state
    >>> law = BilinearRock(loading_stiffness_n_per_m=2e8, unloading_stiffness_n_per_m=8e8)
    >>> force_n, (surface_m, bottom_m) = force_and_state(law, 1e-3, 0.1, law.initial_state())
    >>> force_n, bottom_m  # k_l x; the bottom at x (1 - k_l / k_u)
    (200000.0, 0.00075)
    """

    loading_stiffness_n_per_m: float
    unloading_stiffness_n_per_m: float
    fresh_fraction: float = 1.0  # eta, the share of the next blow on fresh rock (models.drill.indexing)

    name = "bilinear"
    modes_follow_fresh_fraction = False  # eta acts at blow starts only
    state_names = (SURFACE, BOTTOM)
    bottom_index = 1
    threshold_n = math.inf
    damping_n_s_per_m = 0.0

    def __post_init__(self) -> None:
        if not 0 < self.loading_stiffness_n_per_m <= self.unloading_stiffness_n_per_m < math.inf \
                or not 0 < self.fresh_fraction <= 1:
            raise ValueError(f"invalid rock parameters {self}: need 0 < k_l <= k_u < inf")

    @property
    def crushes(self) -> bool:
        """False for k_u = k_l (elastic at k_l: nothing is kept, no per-step update)."""
        return self.unloading_stiffness_n_per_m > self.loading_stiffness_n_per_m

    @property
    def resets_at_blows(self) -> bool:
        """Each blow meets the surface its indexing gives (module doc); an elastic rock keeps none."""
        return self.crushes

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

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend = NUMERIC,
                     fresh_fraction: Any = None) -> Any:
        """F = max(0, min(k_l (x - s), k_u (x - p))) (eta acts at blow starts only)."""
        surface, bottom = state
        loading = self.loading_stiffness_n_per_m * (bit_position_m - surface)
        unloading = self.unloading_stiffness_n_per_m * (bit_position_m - bottom)
        return backend.maximum(backend.minimum(loading, unloading), 0.0)

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any],
              backend: Backend = NUMERIC, fresh_fraction: Any = None) -> Any:
        """The spring force: no rock damping in this law."""
        return self.spring_force(bit_position_m, state, backend)

    def return_map(self, bit_position_m: float, state: State) -> State:
        """p <- max(p, x - k_l (x - s) / k_u), written as s + (1 - k_l / k_u) (x - s) (exactly s for
        an elastic rock); off the rock (x <= p) nothing changes (crater memory)."""
        surface, bottom = state
        if bit_position_m <= bottom:
            return state
        return (surface, max(bottom, surface + self.indentation_ratio * (bit_position_m - surface)))

    def start_blow(self, bit_position_m: float, state: State) -> State:
        """The state the next blow meets (module doc): s <- s + eta (s_fresh - s), s_fresh = min(p,
        x - F / k_l) with F the current spring force (s_fresh = p off the rock)."""
        surface, bottom = state
        fresh = bottom
        if bit_position_m > bottom:
            fresh = min(bottom, bit_position_m - self.spring_force(bit_position_m, state) / self.loading_stiffness_n_per_m)
        return (surface + self.fresh_fraction * (fresh - surface), bottom)

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """W_p = int F dp (trapezoidal; exact on the loading line, where F is linear in p)."""
        return trapezoidal_plastic_work_j(spring_force_n, bottom_m)

    def modes(self) -> ModeTable:
        """The mode table of the module docstring over position x, surface_m s, bottom_m p, velocity v
        and one: F = k_l (x - s) while loading (p' = (1 - k_l / k_u) v; entered at p = s + (1 - k_l / k_u)
        (x - s), the return map on the switching surface), k_u (x - p) while unloading, 0 free or
        lifted (no state changes: the crater is remembered)."""
        k_l, k_u, ratio = self.loading_stiffness_n_per_m, self.unloading_stiffness_n_per_m, self.indentation_ratio
        gap = {POSITION: 1.0, BOTTOM: -1.0}
        loading_exit = Switch({VELOCITY: 1.0}, -1, UNLOADING) if self.crushes else Switch(gap, -1, FREE)
        table = {
            FREE: Mode({}, (Switch(gap, 1, LOADING),)),
            LOADING: Mode({POSITION: k_l, SURFACE: -k_l}, (loading_exit,),
                          rates={BOTTOM: {VELOCITY: ratio}},
                          entry={BOTTOM: {SURFACE: 1.0 - ratio, POSITION: ratio}}),
        }
        if self.crushes:
            reload_margin = {POSITION: k_u - k_l, BOTTOM: -k_u, SURFACE: k_l}  # k_u (x - p) - k_l (x - s)
            table[LIFTED] = Mode({}, (Switch(gap, 1, UNLOADING),))
            table[UNLOADING] = Mode({POSITION: k_u, BOTTOM: -k_u},
                                    (Switch(reload_margin, 1, LOADING), Switch(gap, -1, LIFTED)))
        return table

    def initial_mode(self, values: Mapping[str, float]) -> str:
        """Off the rock: free on a fresh surface (s = p), lifted over a remembered crater; on the rock:
        loading on the loading line (to round-off) unless moving out, else unloading."""
        x, surface, bottom = values[POSITION], values[SURFACE], values[BOTTOM]
        if x <= bottom:
            return FREE if surface >= bottom or not self.crushes else LIFTED
        loading = self.loading_stiffness_n_per_m * (x - surface)
        unloading = self.unloading_stiffness_n_per_m * (x - bottom)
        on_loading_line = unloading >= loading * (1 - 1e-9)
        return LOADING if not self.crushes or (on_loading_line and values[VELOCITY] >= 0) else UNLOADING
