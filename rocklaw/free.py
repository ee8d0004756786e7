"""No rock: the drill string ends free (a rod struck at one end and free at the other, a string lifted off the
bottom). Every force is 0, nothing is crushed or stored, the state (the borehole bottom) never changes: the
law the formulations run where a scene has no rock (``rock: {law: none}``, or no ``drill_string.rock_body``)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .backends import NUMERIC, Backend
from .base import RockLaw, State
from .modes import Mode, ModeTable

FREE = "free"


@dataclass(frozen=True)
class NoRock(RockLaw):
    """The law of no rock (module doc): F = 0 whatever the bit does; the state (the bottom) never changes.

    A :class:`RockLaw`, the one a scene runs with ``rock: {law: none}`` or without a ``drill_string.rock_body``: a
    string that ends free (a rod struck at one end and free at the other).

    Parameters
    ----------
    fresh_fraction : float, default 1.0
        Kept for the interface (bit indexing changes nothing here).

    Examples
    --------
    >>> from rpdrill.rocklaw import NoRock, force_and_state
    >>> law = NoRock()
    >>> force_and_state(law, 1e-3, 0.1, law.initial_state())
    (0.0, (0.0,))
    """

    fresh_fraction: float = 1.0

    name = "none"
    state_names = ("bottom_m",)
    bottom_index = 0
    crushes = False
    loading_stiffness_n_per_m = 0.0
    unloading_stiffness_n_per_m = math.inf  # stores F^2 / (2 k) = 0
    threshold_n = math.inf
    damping_n_s_per_m = 0.0
    crushing_penetration_m = math.inf
    modes_follow_fresh_fraction = False
    resets_at_blows = False

    def initial_state(self) -> State:
        return (0.0,)

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any], backend: Backend = NUMERIC,
              fresh_fraction: Any = None) -> Any:
        """F = 0."""
        return 0.0 * bit_position_m

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend = NUMERIC,
                     fresh_fraction: Any = None) -> Any:
        return 0.0 * bit_position_m

    def return_map(self, bit_position_m: float, state: State) -> State:
        return state

    def start_blow(self, bit_position_m: float, state: State) -> State:
        return state

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        return np.zeros(len(bottom_m))

    def modes(self) -> ModeTable:
        """One mode, no force, no exit."""
        return {FREE: Mode({}, ())}

    def initial_mode(self, values: Mapping[str, float]) -> str:
        return FREE
