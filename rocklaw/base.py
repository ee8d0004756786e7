"""The interface of a bit-rock contact law, which every formulation codes against.

A law has internal states (``state_names``; one of them, ``bottom_index``, is the borehole
bottom x_n, never decreasing) and gives the force on the bit from the bit position x, velocity v
and the state:

* pure functions, written once against :mod:`rocklaw.backends` (branching with
  ``backend.where`` only, so that Exudyn can record them): :meth:`RockLaw.force` (total, >= 0
  pushing the bit out of the hole, unless a law's damping says otherwise) and
  :meth:`RockLaw.spring_force` (its rate-independent part);
* the time-discrete state update of the Exudyn element, :meth:`RockLaw.return_map`, applied once
  per accepted step before the step; it also gives the state consistent with a static preload,
  ``return_map(x_bit0, initial_state())``;
* the ODE side, a mode table: in each mode the states move at :meth:`RockLaw.state_rate`; a mode
  is left at the first zero crossing of one of its :meth:`RockLaw.transitions`, and
  :meth:`RockLaw.enter` gives the state at the start of the next mode;
* energy: the rock stores F_spring^2 / (2 k_unload) and dissipates the plastic (crushing) work
  W_p = int F_spring d(x_n) (:meth:`RockLaw.plastic_work_j`).

Implementations: :class:`rocklaw.jenkins.JenkinsRock` (the paper's Eq. 1, 2) and
:class:`rocklaw.bilinear.BilinearRock`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np
from rpdrill.rocklaw.backends import NUMERIC, Backend
from scipy.integrate import cumulative_trapezoid

State = tuple[float, ...]
# g(bit position [m], bit velocity [m/s], state) whose zero crossing ends a mode
EventFunction = Callable[[float, float, Sequence[float]], float]
# (event function, crossing direction: +1 rising, -1 falling, next mode)
Transition = tuple[EventFunction, int, str]


@runtime_checkable
class RockLaw(Protocol):
    """A bit-rock contact law (module docstring). Lengths in m, forces in N."""

    @property
    def name(self) -> str: ...
    @property
    def state_names(self) -> tuple[str, ...]: ...
    @property
    def bottom_index(self) -> int: ...
    @property
    def crushes(self) -> bool: ...
    @property
    def loading_stiffness_n_per_m(self) -> float: ...
    @property
    def unloading_stiffness_n_per_m(self) -> float: ...
    @property
    def threshold_n(self) -> float: ...
    @property
    def damping_n_s_per_m(self) -> float: ...
    @property
    def crushing_penetration_m(self) -> float:
        """Penetration from the bottom at which crushing starts: the law's length scale
        (Jenkins F_th / k_n; 0 for a law that indents from the first contact; inf if elastic)."""
        ...

    def initial_state(self) -> State:
        """The state of an untouched rock with its surface at x = 0."""
        ...

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any], backend: Backend) -> Any:
        """Total rock force on the bit [N], positive pushing the bit out of the hole."""
        ...

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend) -> Any:
        """The rate-independent part of :meth:`force` [N]."""
        ...

    def return_map(self, bit_position_m: float, state: State) -> State:
        """The state after the bit reached ``bit_position_m`` (once per step, before the step)."""
        ...

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """Cumulative plastic work int F_spring d(x_n) [J] along sampled histories."""
        ...

    def initial_mode(self, bit_position_m: float, bit_velocity_m_per_s: float, state: Sequence[float]) -> str:
        """The ODE mode of a start in this state."""
        ...

    def transitions(self, mode: str) -> list[Transition]:
        """How ``mode`` is left: (event function, direction, next mode)."""
        ...

    def state_rate(self, mode: str, bit_velocity_m_per_s: float) -> State:
        """d(state)/dt in ``mode``."""
        ...

    def enter(self, mode: str, bit_position_m: float, state: State) -> State:
        """The state at the start of a piece in ``mode`` (removes the event location's round-off)."""
        ...


def force_and_state(law: RockLaw, bit_position_m: float, bit_velocity_m_per_s: float,
                    state: State, backend: Backend = NUMERIC) -> tuple[float, State]:
    """One step of the time-discrete law: state <- return_map(x, state), then F(x, v, state)."""
    new_state = law.return_map(bit_position_m, state)
    return law.force(bit_position_m, bit_velocity_m_per_s, new_state, backend), new_state


def trapezoidal_plastic_work_j(spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
    """W_p = int F_spring d(x_n), trapezoidal over the samples (exact where F is linear in x_n)."""
    return cumulative_trapezoid(spring_force_n, bottom_m, initial=0.0)
