"""A rock law (:class:`rocklaw.base.RockLaw`) as an Exudyn element: a coordinate spring-damper
from ground to the bit.

The force is an Exudyn *symbolic* user function recorded from the law's ``force`` (compiled
expression tree, no Python call per evaluation; ``symbolic=False`` gives the same law as a
Python callback, for benchmarks). The law's states are named symbolic ``Real`` variables
``rock_<state name>`` of the expression (plain Python floats with ``symbolic=False``), updated
once per accepted step, before the step, by the law's return map (a pre-step function; a law whose state
moves at a finite rate by its ``step_update`` over the step), and at the
first step that starts at or after each blow start by ``start_blow`` (the state the blow meets), when
the law resets at blow starts.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from exudyn.advancedUtilities import CreateSymbolicUserFunction
from exudyn.itemInterface import ObjectConnectorCoordinateSpringDamper

from .backends import SCALAR, SymbolicBackend
from .base import RockLaw, State

COORDINATE = exu.OutputVariableType.Coordinates
RATE = exu.OutputVariableType.Coordinates_t


def attach_user_function(mbs: Any, item: Any, parameter: str, function: Any, symbolic: bool) -> Any:
    """Set ``function`` as the item's user function: recorded as symbolic (compiled) or as a
    plain Python callback (for comparison). Returns what must be kept alive with the system."""
    if symbolic:
        function = CreateSymbolicUserFunction(mbs, function, parameter, item)
    if item.GetTypeString() == "LoadIndex":
        mbs.SetLoadParameter(item, parameter, function)
    else:
        mbs.SetObjectParameter(item, parameter, function)
    return function


class ExudynRockContact:
    """A rock law between a ground coordinate marker and the bit's coordinate marker.

    The initial state is ``initial_state``, by default the law's state consistent with the bit's
    initial coordinate, return_map(x_bit(0), law.initial_state()) (a static preload).
    ``start_blow(bit position, state)`` gives the state a blow meets; it is applied at the first step
    starting at or after each multiple of ``blow_period_s``.
    """

    def __init__(
        self,
        mbs: Any,
        ground_marker: Any,
        bit_marker: Any,
        bit_node: Any,
        rock: RockLaw,
        symbolic: bool = True,
        initial_state: State | None = None,
        start_blow: Callable[[float, State], State] | None = None,
        blow_period_s: float = float("inf"),
    ) -> None:
        self.rock = rock
        self._start_blow, self._blow_period_s, self._blows = start_blow, blow_period_s, 0
        self._bit_node = bit_node
        self._return_map, self._step_update = rock.return_map, getattr(rock, "step_update", None)
        if initial_state is None:
            initial_position = mbs.GetNodeParameter(bit_node, "initialCoordinates")[0]
            initial_state = rock.return_map(initial_position, rock.initial_state())
        self.state: State = tuple(float(value) for value in initial_state)  # floats: the hook compares them every step
        # (time, state) each time the state changed; the state at t is the step function through these
        self.state_history: list[tuple[float, State]] = [(0.0, self.state)]
        self._step_start_s = 0.0
        # the offset stays 0: the user function sees the bit position as the displacement
        self.object = mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[ground_marker, bit_marker],
                stiffness=rock.loading_stiffness_n_per_m,
                damping=rock.damping_n_s_per_m,
            )
        )
        self._variables = tuple(exu.symbolic.Real(f"rock_{name}", value)
                                for name, value in zip(rock.state_names, self.state, strict=True)) if symbolic else ()
        # eta a variable of the expression where the closed form carries it (it may change per blow)
        self._fresh_fraction = exu.symbolic.Real("rock_fresh_fraction", rock.fresh_fraction) \
            if symbolic and rock.modes_follow_fresh_fraction else None
        backend = SymbolicBackend() if symbolic else SCALAR

        def rock_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
            # recorded once with the symbolic variables, or called at every evaluation with the floats
            if symbolic:
                return rock.force(displacement, velocity, self._variables, backend, self._fresh_fraction)
            return self.rock.force(displacement, velocity, self.state, backend)

        # Exudyn keeps only a raw pointer to a symbolic expression tree: hold the reference here.
        self._user_function = attach_user_function(
            mbs, self.object, "springForceUserFunction", rock_force, symbolic
        )

    @property
    def bottom_history(self) -> list[tuple[float, float]]:
        """(time, borehole bottom x_n) at the start and at every change of the state."""
        return [(t, state[self.rock.bottom_index]) for t, state in self.state_history]

    def set_state(self, state: State, time_s: float) -> None:
        """Make ``state`` the law's state from ``time_s`` on (in the compiled expression too)."""
        for variable, old, new in zip(self._variables, self.state, state):
            if new != old:
                variable.SetValue(new)
        self.state = state
        self.state_history.append((time_s, state))

    def start_at(self, state: State) -> None:
        """Make ``state`` the law's initial state (before the run: a start solved after the build)."""
        state = tuple(float(value) for value in state)
        for variable, value in zip(self._variables, state):
            variable.SetValue(value)
        self.state, self.state_history = state, [(0.0, state)]

    def set_law(self, rock: RockLaw) -> None:
        """Go on with ``rock`` (the same law with another eta: models.drill.indexing), in the expression too."""
        if self._fresh_fraction is not None and rock.fresh_fraction != self.rock.fresh_fraction:
            self._fresh_fraction.SetValue(rock.fresh_fraction)
        self.rock, self._return_map, self._step_update = rock, rock.return_map, getattr(rock, "step_update", None)

    def state_at(self, times_s: np.ndarray) -> np.ndarray:
        """The state (samples x states) at ``times_s``: the last change at or before each time."""
        stamps = np.array([t for t, _ in self.state_history])
        states = np.array([state for _, state in self.state_history])
        return states[np.clip(np.searchsorted(stamps, times_s, side="right") - 1, 0, None)]

    def update_bottom(self, mbs: Any, t: float) -> bool:
        """The law's return map at the current bit position (a law with ``step_update``: its update over
        the coming step from the bit's position and velocity), called once before each step.

        Exudyn passes the pre-step function the time at the *end* of the coming step while the
        state is still that of its start; the history is stamped with the start time.
        """
        position = mbs.GetNodeOutput(self._bit_node, COORDINATE)
        if self._step_update is None:
            state = self._return_map(position, self.state)
        else:  # a law whose state moves at a finite rate: its update over the coming step
            state = self._step_update(position, mbs.GetNodeOutput(self._bit_node, RATE), self.state,
                                      t - self._step_start_s)
        # a step start a round-off before a blow start is that blow start
        if self._start_blow is not None and self._step_start_s >= (self._blows - 1e-9) * self._blow_period_s:
            state = self._start_blow(position, state)
            self._blows += 1
        if state != self.state:
            self.set_state(state, self._step_start_s)
        self._step_start_s = t
        return True  # as an Exudyn pre-step function: go on
